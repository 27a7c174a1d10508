// What the station accepts as a serial number: 1 to 64 characters from A-Z a-z 0-9 and
// "-_.:#+", starting with a letter or digit. Everything else is refused before a test, so
// every stored serial can be read back as one URL path segment (GET /api/units/{serial};
// '/' was stored but unreachable) and written into CSV and file names unquoted. '#' and '+'
// must be percent-encoded in URLs (%23, %2B).
#pragma once

#include <string>

namespace eol::db {

bool ValidSerial(const std::string& serial, std::string* why);

}  // namespace eol::db
