// Test support: a real PostgreSQL 15 server (Debian's postgresql-15) in a temporary
// directory, on a free TCP port of 127.0.0.1 and a unix socket in that directory, stopped by
// its own pid. PostgreSQL refuses to run as root: under root (here and on CI) the cluster is
// made and run as the package's `postgres` system user (setpriv, the directory owned by it);
// as any other user it runs as that user. When neither is possible the caller skips, with
// the reason from Available().
#pragma once

#include <pwd.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "tests/support/child_process.h"

namespace eol::testing {

class PostgresServer {
 public:
  static constexpr const char* kBin = "/usr/lib/postgresql/15/bin";

  // Empty when a server can be run here, else why not (for GTEST_SKIP).
  static std::string Available() {
    if (access((std::string(kBin) + "/postgres").c_str(), X_OK) != 0)
      return std::string(kBin) +
             "/postgres not found: install postgresql-15 (a test package of "
             "deploy/install-deps.sh)";
    if (geteuid() == 0 && getpwnam("postgres") == nullptr)
      return "running as root and there is no 'postgres' user to run PostgreSQL as (PostgreSQL "
             "refuses root); install postgresql-15, which creates it";
    return "";
  }

  // `port`: a free TCP port. Makes the cluster (initdb, trust authentication, user "eol").
  explicit PostgresServer(int port) : port_(port) {
    dir_ = tmp_.path() + "/pg";
    std::filesystem::create_directory(dir_);
    if (geteuid() == 0) {
      const passwd* pw = getpwnam("postgres");
      uid_ = pw->pw_uid;
      gid_ = pw->pw_gid;
      // The test's TempDir is 0700 root: the server's user must reach its own directory.
      chmod(tmp_.path().c_str(), 0711);
      if (chown(dir_.c_str(), uid_, gid_) != 0) throw std::runtime_error("chown " + dir_);
    }
    ChildProcess initdb(
        AsServerUser({std::string(kBin) + "/initdb", "-D", dir_ + "/data", "-U", "eol", "-A",
                      "trust", "-E", "UTF8", "--locale=C", "--no-sync"}));
    const auto rc = initdb.Wait(std::chrono::seconds(120));
    if (!rc || *rc != 0) throw std::runtime_error("initdb failed: " + initdb.output());
  }
  ~PostgresServer() { Stop(); }
  PostgresServer(const PostgresServer&) = delete;
  PostgresServer& operator=(const PostgresServer&) = delete;

  // Starts the server and waits until it accepts connections; "" or the server's output.
  std::string Start() {
    process_ = std::make_unique<ChildProcess>(AsServerUser(
        {std::string(kBin) + "/postgres", "-D", dir_ + "/data", "-p", std::to_string(port_), "-h",
         "127.0.0.1", "-k", dir_, "-c", "max_connections=60", "-c", "shared_buffers=32MB"}));
    if (!process_->WaitFor(
            [](const std::string& o) {
              return o.find("ready to accept connections") != std::string::npos;
            },
            std::chrono::seconds(60)))
      return "postgres did not start: " + process_->output();
    return "";
  }
  // What `pg_ctl stop -m immediate` does: SIGQUIT to the postmaster (no checkpoint; the next
  // start recovers from the WAL, as after a crash).
  void StopImmediate() {
    if (process_) process_->Stop(SIGQUIT, std::chrono::seconds(30));
    process_.reset();
  }
  // A clean (fast) shutdown.
  void Stop() {
    if (process_) process_->Stop(SIGINT, std::chrono::seconds(30));
    process_.reset();
  }

  int port() const { return port_; }
  std::string url() const {
    return "postgresql://eol@127.0.0.1:" + std::to_string(port_) + "/postgres";
  }
  std::string output() const { return process_ ? process_->output() : ""; }

 private:
  // argv run as the server's user: itself when not root, else through setpriv (which execs:
  // the pid the test holds is the server's own).
  std::vector<std::string> AsServerUser(std::vector<std::string> argv) const {
    if (geteuid() != 0) return argv;
    std::vector<std::string> wrapped = {"/usr/bin/setpriv", "--reuid=" + std::to_string(uid_),
                                        "--regid=" + std::to_string(gid_), "--clear-groups", "--"};
    wrapped.insert(wrapped.end(), argv.begin(), argv.end());
    return wrapped;
  }

  TempDir tmp_;
  std::string dir_;
  int port_;
  uid_t uid_ = 0;
  gid_t gid_ = 0;
  std::unique_ptr<ChildProcess> process_;
};

}  // namespace eol::testing
