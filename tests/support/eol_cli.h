// Runs the `eol` binary under test (EOL_BINARY) with arguments and collects its exit code and
// output, for the CLI tests.
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/child_process.h"

namespace eol::testing {

struct CliRun {
  int code = -1;    // -1: did not exit within the timeout
  std::string out;  // stdout, and stderr when merged
};

inline CliRun RunEol(std::vector<std::string> args, bool merge_stderr,
                     std::chrono::seconds timeout) {
  args.insert(args.begin(), EOL_BINARY);
  ChildProcess p(args, merge_stderr);
  const auto code = p.Wait(timeout);
  return CliRun{code.value_or(-1), p.output()};
}

}  // namespace eol::testing
