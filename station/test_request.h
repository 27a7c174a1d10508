// A request to test one unit, as it arrives over HTTP, from the line PLC or the scanner.
#pragma once

#include <string>

namespace eol::station {

struct TestRequest {
  std::string serial;  // station/serial_number.h says what is accepted
};

}  // namespace eol::station
