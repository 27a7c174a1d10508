// Shared plumbing of the Modbus peer tests: the independent peers are Debian's
// python3-pymodbus (run with /usr/bin/python3) and socat. They are declared dependencies,
// so a missing one fails the test with the install hint; it never skips.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tests/support/child_process.h"

namespace eol::testing::modbus_peers {

inline constexpr const char* kPython = "/usr/bin/python3";
inline constexpr const char* kSocat = "/usr/bin/socat";

inline std::string PeerScript(const std::string& name) {
  return std::string(EOL_SOURCE_DIR) + "/tests/peers/" + name;
}

inline ::testing::AssertionResult PymodbusAvailable() {
  if (access(kPython, X_OK) != 0)
    return ::testing::AssertionFailure()
           << kPython << " not found: python3 with python3-pymodbus is a declared dependency";
  ChildProcess probe({kPython, "-c", "import pymodbus; print(pymodbus.__version__)"});
  const auto code = probe.Wait(std::chrono::seconds(30));
  if (code != 0)
    return ::testing::AssertionFailure()
           << "python3-pymodbus is missing for " << kPython
           << " (a declared dependency: apt-get install python3-pymodbus): " << probe.output();
  return ::testing::AssertionSuccess();
}

inline ::testing::AssertionResult SocatAvailable() {
  if (access(kSocat, X_OK) != 0)
    return ::testing::AssertionFailure()
           << kSocat << " not found: socat is a declared dependency (apt-get install socat)";
  return ::testing::AssertionSuccess();
}

// Waits until `child` has written a port number to `ready_file` (atomically, by rename);
// nullopt when the child exits first or the timeout passes.
inline std::optional<int> WaitForReadyPort(ChildProcess& child, const std::string& ready_file,
                                           std::chrono::milliseconds timeout) {
  const bool ready = child.WaitFor(
      [&](const std::string&) { return std::filesystem::exists(ready_file); }, timeout);
  if (!ready) return std::nullopt;
  std::ifstream in(ready_file);
  int port = 0;
  if (!(in >> port) || port <= 0) return std::nullopt;
  return port;
}

// Runs a pymodbus client script of tests/peers/ (pymodbus_fixture_client.py, or
// pymodbus_plc_client.py for the line PLC) to completion and returns its JSON results (one
// per operation); a JSON null when it failed or took longer than `timeout` (the reason is in
// `log`).
inline nlohmann::json RunPymodbusClientScript(
    const std::string& script, const std::vector<std::string>& transport_args,
    const nlohmann::json& ops, std::string* log,
    std::chrono::seconds timeout = std::chrono::seconds(60)) {
  std::vector<std::string> argv = {kPython, PeerScript(script)};
  argv.insert(argv.end(), transport_args.begin(), transport_args.end());
  argv.push_back("--ops");
  argv.push_back(ops.dump());
  ChildProcess client(argv, /*merge_stderr=*/false);
  const auto code = client.Wait(timeout);
  *log = "exit " + (code ? std::to_string(*code) : std::string("none (timed out)")) +
         ", stdout: " + client.output();
  if (code != 0) return nullptr;
  try {
    return nlohmann::json::parse(client.output());
  } catch (const nlohmann::json::exception&) {
    return nullptr;
  }
}

inline nlohmann::json RunPymodbusClient(const std::vector<std::string>& transport_args,
                                        const nlohmann::json& ops, std::string* log) {
  return RunPymodbusClientScript("pymodbus_fixture_client.py", transport_args, ops, log);
}

}  // namespace eol::testing::modbus_peers
