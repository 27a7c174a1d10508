// Test support: waits for a condition instead of sleeping for a fixed time. Polls every 5 ms
// until it holds or the deadline passes. The deadline only bounds a broken run and is never
// a pass/fail threshold: a test states what it waits for and asserts on the result.
#pragma once

#include <chrono>
#include <thread>

namespace eol::testing {

// Long enough for the slowest healthy run on a loaded 2-core machine (a daemon starting,
// a database recovering), short enough to end a broken run.
inline constexpr std::chrono::seconds kGenerousDeadline{60};

// True as soon as done() holds, false when it still does not at the deadline. done() is
// called once per look (it may act: send a request, read a file), never again after it held.
template <typename F>
bool WaitUntil(F done, std::chrono::milliseconds timeout = kGenerousDeadline) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace eol::testing
