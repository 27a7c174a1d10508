// Test support: waits for a condition instead of sleeping for a fixed time. Polls (every
// 20 ms unless told) until it holds or the deadline passes. The deadline only bounds a broken run
// and is never a pass/fail threshold: a test states what it waits for and asserts on the result.
#pragma once

#include <chrono>
#include <thread>

namespace eol::testing {

// Long enough for the slowest healthy run on a loaded 2-core machine (a daemon starting,
// a database recovering), short enough to end a broken run.
inline constexpr std::chrono::seconds kGenerousDeadline{60};

// True as soon as done() holds, false when it still does not at the deadline. done() is
// called once per look (it may act: send a request, read a file), never again after it held;
// `poll` apart (a look that opens a connection to a daemon: 50 ms, so as not to load it).
template <typename F>
bool WaitUntil(F done, std::chrono::milliseconds timeout = kGenerousDeadline,
               std::chrono::milliseconds poll = std::chrono::milliseconds(20)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(poll);
  }
}

}  // namespace eol::testing
