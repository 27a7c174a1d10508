// Test support: a PulseAudio server with one null sink "eol_null", owned by the test (own
// HOME, runtime dir and socket), reached through the "pulse" ALSA plugin
// (libasound2-plugins): playback to "pulse:eol_null", capture from "pulse:eol_null.monitor".
// As root it needs its own HOME and XDG_RUNTIME_DIR, no idle exit, and no shared memory.
// While it lives, PULSE_SERVER points at it. Stopped by its own pid.
#pragma once

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/child_process.h"

namespace eol::testing {

inline bool CanConnectUnix(const std::string& socket_path) {
  const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  if (fd < 0) return false;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", socket_path.c_str());
  const bool ok = connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  close(fd);
  return ok;
}

class PulseServer {
 public:
  PulseServer() {
    socket_ = dir_ / "native";
    const std::string pulse = "/usr/bin/pulseaudio";
    if (!std::filesystem::exists(pulse)) return;
    server_ = std::make_unique<ChildProcess>(std::vector<std::string>{
        "/usr/bin/env", "HOME=" + dir_.path(), "XDG_RUNTIME_DIR=" + dir_.path(), pulse,
        "--daemon=no", "--exit-idle-time=-1", "-n", "--use-pid-file=no", "--disable-shm=yes",
        "--log-target=stderr",
        "--load=module-null-sink sink_name=eol_null rate=48000 channels=2 format=float32le",
        "--load=module-native-protocol-unix auth-anonymous=1 socket=" + socket_});
    // Waited for until its socket answers (10 s at most: it bounds a broken start only).
    for (int i = 0; i < 100 && !ready_; ++i) {
      ready_ = CanConnectUnix(socket_);
      if (!ready_) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (ready_) setenv("PULSE_SERVER", ("unix:" + socket_).c_str(), 1);
  }
  ~PulseServer() {
    unsetenv("PULSE_SERVER");
    if (server_) server_->Stop(SIGTERM, std::chrono::milliseconds(5000));
  }
  PulseServer(const PulseServer&) = delete;
  PulseServer& operator=(const PulseServer&) = delete;

  bool ready() const { return ready_; }
  std::string why_not() const {
    if (!server_) return "pulseaudio is not installed (Debian package pulseaudio)";
    return "pulseaudio did not open " + socket_ + ": " + server_->output();
  }

 private:
  TempDir dir_;
  std::string socket_;
  std::unique_ptr<ChildProcess> server_;
  bool ready_ = false;
};

}  // namespace eol::testing
