// The HTTP port a started `eol station` announces on its start line
// ("eol station: <id> ready, recipe ..., http://127.0.0.1:<port>/", or "<id> up, NOT READY
// (<why>), recipe ..." when the fixture or the DAQ did not answer yet); 0 until it has.
#pragma once

#include <regex>
#include <string>

namespace eol::testing {

inline int PortFromReadyLine(const std::string& out) {
  std::smatch m;
  static const std::regex re("eol station: .*, recipe .* http://127\\.0\\.0\\.1:([0-9]+)/");
  return std::regex_search(out, m, re) ? std::stoi(m[1]) : 0;
}

}  // namespace eol::testing
