// Test support: polls a condition every 20 ms until it holds or the timeout passes.
#pragma once

#include <chrono>
#include <thread>

namespace eol::testing {

// Returns done() after the last look: true when it held within `timeout`.
template <typename F>
bool WaitUntil(F done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!done() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return done();
}

}  // namespace eol::testing
