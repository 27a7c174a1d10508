#include "station/serial_number.h"

namespace eol::station {

bool ValidSerial(const std::string& s, std::string* why) {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (s.empty()) return fail("serial is empty");
  if (s.size() > 64) return fail("serial is longer than 64 characters");
  for (unsigned char c : s)
    if (c < 0x20 || c > 0x7e) return fail("serial contains a control or non-ASCII character");
  if (s.front() == ' ' || s.back() == ' ') return fail("serial starts or ends with a space");
  return true;
}

}  // namespace eol::station
