#include "station/daemon/test_request.h"

#include <sstream>

#include "db/serial_number.h"

namespace eol::station {
namespace {

bool ValidField(const char* name, const std::string& text, std::size_t max_chars,
                std::string* why) {
  if (text.size() > max_chars) {
    *why = std::string(name) + ": at most " + std::to_string(max_chars) + " characters (got " +
           std::to_string(text.size()) + ")";
    return false;
  }
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c > 0x7E) {
      *why = std::string(name) + ": character " + std::to_string(i + 1) + " is not printable ASCII";
      return false;
    }
  }
  if (!text.empty() && (text.front() == ' ' || text.back() == ' ')) {
    *why = std::string(name) + ": no spaces at either end";
    return false;
  }
  return true;
}

// The fields in one place, for the JSON, the scanner and the messages.
struct FieldSpec {
  const char* name;
  std::string db::WorkContext::*member;
  std::size_t max_chars;
};
constexpr FieldSpec kFields[] = {
    {"operator_id", &db::WorkContext::operator_id, kMaxOperatorIdChars},
    {"shift", &db::WorkContext::shift, kMaxShiftChars},
    {"order_number", &db::WorkContext::order_number, kMaxOrderNumberChars},
};

}  // namespace

bool ValidWorkContext(const db::WorkContext& work, std::string* why) {
  for (const FieldSpec& f : kFields)
    if (!ValidField(f.name, work.*(f.member), f.max_chars, why)) return false;
  return true;
}

bool ReadWorkContext(const nlohmann::json& body, db::WorkContext* work, std::string* why) {
  for (const FieldSpec& f : kFields) {
    if (!body.contains(f.name) || body[f.name].is_null()) continue;
    if (!body[f.name].is_string()) {
      *why = std::string(f.name) + ": must be a string";
      return false;
    }
    work->*(f.member) = body[f.name].get<std::string>();
  }
  return ValidWorkContext(*work, why);
}

std::optional<TestRequest> ParseScannerLine(const std::string& line, std::string* why) {
  TestRequest r;
  std::istringstream in(line);
  std::string field;
  std::getline(in, r.serial, '\t');
  if (!db::ValidSerial(r.serial, why)) return std::nullopt;
  bool seen[std::size(kFields)] = {};
  while (std::getline(in, field, '\t')) {
    const std::size_t eq = field.find('=');
    if (eq == std::string::npos) {
      *why = "field '" + field + "' is not key=value (keys: operator_id, shift, order_number)";
      return std::nullopt;
    }
    const std::string key = field.substr(0, eq);
    std::size_t k = 0;
    while (k < std::size(kFields) && key != kFields[k].name) ++k;
    if (k == std::size(kFields)) {
      *why = "unknown field '" + key + "' (keys: operator_id, shift, order_number)";
      return std::nullopt;
    }
    if (seen[k]) {
      *why = "field '" + key + "' given twice";
      return std::nullopt;
    }
    seen[k] = true;
    r.work.*(kFields[k].member) = field.substr(eq + 1);
  }
  if (!ValidWorkContext(r.work, why)) return std::nullopt;
  return r;
}

}  // namespace eol::station
