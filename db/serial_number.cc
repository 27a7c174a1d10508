#include "db/serial_number.h"

#include <string_view>

namespace eol::db {

bool ValidSerial(const std::string& s, std::string* why) {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (s.empty()) return fail("serial is empty");
  if (s.size() > 64) return fail("serial is longer than 64 characters");
  auto alnum = [](unsigned char c) {
    return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
  };
  if (!alnum(static_cast<unsigned char>(s.front())))
    return fail("serial must start with a letter or digit");
  for (unsigned char c : s)
    if (!alnum(c) && std::string_view("-_.:#+").find(static_cast<char>(c)) == std::string::npos)
      return fail("serial may hold only A-Z a-z 0-9 and -_.:#+ (found " +
                  (c >= 0x21 && c <= 0x7e ? "'" + std::string(1, static_cast<char>(c)) + "'"
                                          : "byte " + std::to_string(c)) +
                  ")");
  return true;
}

}  // namespace eol::db
