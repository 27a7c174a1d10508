// Shared by the libFuzzer targets (tests/fuzz/*_fuzzer.cc): the input as a file for the file
// readers, and one way to report a broken contract. A target calls Finding() for a result
// its reader's header forbids; crashes, leaks and undefined behaviour are reported by the
// sanitizers, and an exception of a type the contract does not name escapes to libFuzzer
// ("deadly signal" through std::terminate) after FailOnException() printed it.
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

namespace eol::fuzz {

// The bytes as a file the readers can open by name: one memfd, rewritten for every input,
// named through /proc/self/fd (no disk traffic, nothing left behind). The name has no
// extension, so readers that dispatch on it are called directly.
inline std::string AsFile(const std::uint8_t* data, std::size_t size) {
  static const int fd = [] {
    const int f = memfd_create("eol-fuzz-input", 0);
    if (f < 0) {
      std::perror("memfd_create");
      std::abort();
    }
    return f;
  }();
  if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != static_cast<ssize_t>(size)) {
    std::perror("writing the fuzz input to the memfd");
    std::abort();
  }
  return "/proc/self/fd/" + std::to_string(fd);
}

[[noreturn]] inline void Finding(const std::string& what) {
  std::fprintf(stderr, "FINDING: %s\n", what.c_str());
  std::abort();
}

// Call in a catch (...) after the documented error types: names the stray exception.
[[noreturn]] inline void FailOnException(const char* reader) {
  try {
    throw;
  } catch (const std::exception& e) {
    Finding(std::string(reader) + " threw an undocumented exception: " + e.what());
  } catch (...) {
    Finding(std::string(reader) + " threw a non-std exception");
  }
}

inline bool AllFinite(const auto& values) {
  for (const auto& v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace eol::fuzz
