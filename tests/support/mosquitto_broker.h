// Test support: a real mosquitto broker (Debian's mosquitto, /usr/sbin/mosquitto) on
// 127.0.0.1:port, started and stopped by the test, with persistence in `<dir>/broker`: what it
// holds survives a restart (the MES's persistent session with its subscription and queued
// messages). Stop() is SIGTERM, which saves the sessions, and fails the test when the save did
// not work. Uses GoogleTest's assertions.
//
// Started as root, mosquitto drops its privileges to the `mosquitto` user after reading its
// config, and writes its persistence file as that user. In the test's own directory (root's,
// 0700) its save on SIGTERM failed ("Error saving in-memory database ... Permission denied"),
// the restarted broker had no session for the MES, and what the station published before the
// MES had subscribed again went to nobody, acknowledged. So the broker's directory belongs to
// the user it runs as, and Stop() checks that the save worked.
#pragma once

#include <gtest/gtest.h>
#include <pwd.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tests/support/child_process.h"

namespace eol::testing {

class MosquittoBroker {
 public:
  static constexpr const char* kMosquitto = "/usr/sbin/mosquitto";

  // `listener_extra`: lines after the listener (its TLS files; "BROKER" stands for dir()),
  // given a prepare step that writes files into dir() first (they are given to the broker's
  // user too).
  MosquittoBroker(std::string dir, int port, std::string listener_extra = "",
                  const std::function<void(const std::string&)>& prepare = {})
      : dir_(std::move(dir) + "/broker"), port_(port) {
    std::filesystem::create_directory(dir_);
    if (geteuid() == 0) {
      if (const passwd* pw = getpwnam("mosquitto")) {
        chmod(std::filesystem::path(dir_).parent_path().c_str(), 0711);
        if (chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) ADD_FAILURE() << "chown " << dir_;
      }
    }
    if (prepare) prepare(dir_);
    for (std::size_t at; (at = listener_extra.find("BROKER")) != std::string::npos;)
      listener_extra.replace(at, 6, dir_);
    if (geteuid() == 0)
      if (const passwd* pw = getpwnam("mosquitto"))
        for (const auto& f : std::filesystem::directory_iterator(dir_))
          if (chown(f.path().c_str(), pw->pw_uid, pw->pw_gid) != 0) ADD_FAILURE() << f.path();
    std::ofstream(dir_ + "/mosquitto.conf")
        << "listener " << port_ << " 127.0.0.1\n"
        << listener_extra << "allow_anonymous true\npersistence true\n"
        << "persistence_location " << dir_
        << "/\n"
        // The MES's session queues the whole replay while it reconnects (mosquitto drops
        // QoS 1 messages beyond 1000 queued per client by default).
        << "max_queued_messages 100000\n";
  }
  MosquittoBroker(const MosquittoBroker&) = delete;
  MosquittoBroker& operator=(const MosquittoBroker&) = delete;

  // Starts the broker and waits until it runs (10 s).
  ::testing::AssertionResult Start() {
    using namespace std::chrono_literals;
    if (access(kMosquitto, X_OK) != 0)
      return ::testing::AssertionFailure()
             << kMosquitto << " not found: mosquitto is a declared test dependency "
             << "(apt-get install mosquitto)";
    process_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kMosquitto, "-c", dir_ + "/mosquitto.conf"});
    if (!process_->WaitFor(
            [](const std::string& o) { return o.find(" running") != std::string::npos; }, 10s))
      return ::testing::AssertionFailure() << "mosquitto did not start: " << process_->output();
    return ::testing::AssertionSuccess();
  }
  // SIGTERM: mosquitto saves its sessions to persistence_location, then exits. A failed
  // save fails the test: the next start would have lost the sessions.
  void Stop() {
    using namespace std::chrono_literals;
    if (!process_) return;
    process_->Stop(SIGTERM, 10s);
    EXPECT_EQ(process_->output().find("Error saving"), std::string::npos) << process_->output();
    EXPECT_TRUE(std::filesystem::exists(dir_ + "/mosquitto.db"))
        << "mosquitto saved no persistence file: " << process_->output();
    process_.reset();
  }
  int port() const { return port_; }
  const std::string& dir() const { return dir_; }
  // What the running broker printed so far ("" when stopped).
  std::string output() {
    if (!process_) return "";
    process_->WaitFor([](const std::string&) { return false; }, std::chrono::milliseconds(50));
    return process_->output();
  }

 private:
  std::string dir_;
  int port_;
  std::unique_ptr<ChildProcess> process_;
};

}  // namespace eol::testing
