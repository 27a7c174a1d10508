// Test support: the plant's MES, played by an independent MQTT client
// (tests/peers/mqtt_subscriber.py on Debian's python3-paho-mqtt, a QoS 1 persistent session),
// run as a ChildProcess, and what it received, parsed from its output.
#pragma once

#include <chrono>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/child_process.h"

namespace eol::testing {

constexpr const char* kMesPython = "/usr/bin/python3";

// The subscriber's command line: `topic` on 127.0.0.1:port, then `extra` arguments
// ("--client-id", "--cafile" ...).
inline std::vector<std::string> MesArgv(int port, const std::string& topic,
                                        const std::vector<std::string>& extra = {}) {
  std::vector<std::string> argv = {
      kMesPython, std::string(EOL_SOURCE_DIR) + "/tests/peers/mqtt_subscriber.py",
      "--port",   std::to_string(port),
      "--topic",  topic};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return argv;
}

// Waits until the subscriber's SUBSCRIBE was acknowledged (it prints "subscribed").
inline bool WaitSubscribed(ChildProcess& mes, std::chrono::milliseconds timeout) {
  return mes.WaitFor(
      [](const std::string& o) { return o.find("\"subscribed\"") != std::string::npos; }, timeout);
}

// One message the MES received.
struct Received {
  std::string topic;
  std::string payload;
  double t = 0;  // unix seconds, when it arrived
};

// Every message received so far, in arrival order (reads what the process printed).
inline std::vector<Received> Messages(ChildProcess& sub) {
  sub.WaitFor([](const std::string&) { return false; }, std::chrono::milliseconds(20));
  std::vector<Received> out;
  std::istringstream in(sub.output());
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line.front() != '{') continue;
    const auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || j.value("event", "") != "message") continue;
    out.push_back({j["topic"], j["payload"], j["t"]});
  }
  return out;
}

// Test ids (the payload's "id", the idempotency key) of the messages on `topic`: first
// arrivals in arrival order; *duplicates gets how many arrived again.
inline std::vector<std::int64_t> ResultIds(const std::vector<Received>& all,
                                           const std::string& topic, int* duplicates) {
  std::vector<std::int64_t> ids;
  std::set<std::int64_t> seen;
  *duplicates = 0;
  for (const Received& m : all) {
    if (m.topic != topic) continue;
    const auto j = nlohmann::json::parse(m.payload);
    const std::int64_t id = j.at("id");
    if (seen.insert(id).second)
      ids.push_back(id);
    else
      ++*duplicates;
  }
  return ids;
}

}  // namespace eol::testing
