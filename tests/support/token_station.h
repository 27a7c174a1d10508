// The configuration the API tests start `eol station` with: simulated fixture and DAQ, HTTP on
// a free port of 127.0.0.1, one operator token ("line-op") and one engineer token ("qe-anna").
// A test adds what it needs on top (a "sim" block, the DAQ's time scale).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace eol::testing {

inline nlohmann::json TokenStationConfig(const std::string& station_id, const std::string& recipe,
                                         const std::string& operator_token,
                                         const std::string& engineer_token) {
  return {{"station_id", station_id},
          {"recipe", recipe},
          {"db", "s.sqlite"},
          {"http",
           {{"listen", "127.0.0.1"},
            {"port", 0},
            {"tokens",
             {{{"name", "line-op"}, {"role", "operator"}, {"token", operator_token}},
              {{"name", "qe-anna"}, {"role", "engineer"}, {"token", engineer_token}}}}}},
          {"fixture", {{"driver", "sim"}}},
          {"daq", {{"driver", "sim"}}}};
}

}  // namespace eol::testing
