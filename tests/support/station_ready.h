// The HTTP port a started `eol station` announces on its ready line
// ("eol station: <id> ready, recipe ..., http://127.0.0.1:<port>/"); 0 until it has.
#pragma once

#include <regex>
#include <string>

namespace eol::testing {

inline int PortFromReadyLine(const std::string& out) {
  std::smatch m;
  static const std::regex re("ready, .* http://127\\.0\\.0\\.1:([0-9]+)/");
  return std::regex_search(out, m, re) ? std::stoi(m[1]) : 0;
}

}  // namespace eol::testing
