// What the station accepts as a serial number: 1 to 64 printable ASCII characters, no
// spaces at either end, no control characters. Everything else is refused before a test.
#pragma once

#include <string>

namespace eol::station {

bool ValidSerial(const std::string& serial, std::string* why);

}  // namespace eol::station
