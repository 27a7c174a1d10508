// A request to test one unit, as it arrives over HTTP, from the line PLC or the scanner: the
// serial, and who tests it for which order (db::WorkContext, stored with the record).
//
// Accepted: the serial as db/serial_number.h says; operator_id and order_number of at
// most 32 characters, shift of at most 16, each printable ASCII (0x20..0x7E) with no space
// at either end, or empty (not given). The line PLC's registers hold exactly these lengths
// (station/daemon/plc/plc_map.h).
//
// The scanner's line (stdin, with "serial_from_stdin"): the serial alone, or the serial and
// TAB-separated key=value fields named as in the JSON, in any order, each at most once:
//
//   SN-1234<TAB>operator_id=op-17<TAB>shift=B<TAB>order_number=PO-4711
//
// A serial can never hold a TAB, so the line cannot be misread; an unknown key, a field
// without '=' or a key given twice refuses the whole line.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "db/test_record.h"
#include "station/daemon/variants.h"

namespace eol::station {

struct TestRequest {
  std::string serial;
  db::WorkContext work;
  // The variant the request names (station/daemon/variants.h): the operator's choice by name
  // (POST /api/tests "variant") or the line PLC's variant register. Neither (the scanner's
  // line names none): the serial's part-number rules pick it.
  VariantChoice variant;
};

inline constexpr std::size_t kMaxOperatorIdChars = 32;
inline constexpr std::size_t kMaxShiftChars = 16;
inline constexpr std::size_t kMaxOrderNumberChars = 32;

// False with the reason, naming the field ("operator_id: ..."), when a field is not accepted.
bool ValidWorkContext(const db::WorkContext& work, std::string* why);
// The optional string fields "operator_id", "shift" and "order_number" of a JSON object (the
// body of POST /api/tests) into `work`; false naming the field when one is not a string or
// not accepted.
bool ReadWorkContext(const nlohmann::json& body, db::WorkContext* work, std::string* why);
// One scanner line (without its newline); nullopt with the reason when it is refused.
std::optional<TestRequest> ParseScannerLine(const std::string& line, std::string* why);

}  // namespace eol::station
