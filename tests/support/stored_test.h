// Runs one test on a started `eol station` over its HTTP API and waits until its record is
// stored: POST /api/tests {"serial"}, then GET /api/units/<serial> until the newest test has
// finished_at. The previous test's record is stored before the station is idle again (it
// unclamps and publishes after), so a start that meets 409 busy is retried for up to 10 s.
#pragma once

#include <httplib.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

namespace eol::testing {

// The serial's newest test (GET /api/units lists newest first) once it has finished_at, polled
// every 50 ms; null when none has within `timeout`.
inline nlohmann::json WaitForStoredTest(httplib::Client& http, const std::string& serial,
                                        std::chrono::milliseconds timeout) {
  using namespace std::chrono_literals;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  do {
    const httplib::Result unit = http.Get("/api/units/" + serial);
    if (unit && unit->status == 200) {
      const nlohmann::json tests = nlohmann::json::parse(unit->body)["tests"];
      if (!tests.empty() && !tests.front()["finished_at"].get<std::string>().empty())
        return tests.front();
    }
    std::this_thread::sleep_for(50ms);
  } while (std::chrono::steady_clock::now() < deadline);
  return nlohmann::json();
}

// The stored test's summary (the unit's newest entry), or null with *why set: not started
// (no answer, or the status and body of the refusal) or not stored within 30 s.
inline nlohmann::json RunStoredTest(httplib::Client& http, const std::string& serial,
                                    const httplib::Headers& headers = {},
                                    std::string* why = nullptr) {
  using namespace std::chrono_literals;
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return nlohmann::json();
  };
  auto start = [&] {
    return http.Post("/api/tests", headers, nlohmann::json{{"serial", serial}}.dump(),
                     "application/json");
  };
  httplib::Result res = start();
  for (int i = 0; i < 200 && res && res->status == 409; ++i) {
    std::this_thread::sleep_for(50ms);
    res = start();
  }
  if (!res) return fail("not started: no answer");
  if (res->status != 202)
    return fail("not started: " + std::to_string(res->status) + " " + res->body);
  const nlohmann::json test = WaitForStoredTest(http, serial, 30s);
  return test.is_null() ? fail("timeout") : test;
}

}  // namespace eol::testing
