#include "station/daemon/plc/plc_map.h"

#include <algorithm>
#include <array>
#include <cstdio>

#include "drivers/io/json_config.h"

namespace eol::station::plc {
namespace {

enum class Table { kCoil, kDiscreteInput, kInputRegister, kHoldingRegister };

const char* TableName(Table t) {
  switch (t) {
    case Table::kCoil:
      return "coil";
    case Table::kDiscreteInput:
      return "discrete input";
    case Table::kInputRegister:
      return "input register";
    case Table::kHoldingRegister:
      return "holding register";
  }
  return "?";
}

struct SignalSpec {
  const char* name;
  int PlcMap::*member;
  Table table;
  int width;  // addresses taken
};

constexpr std::array<SignalSpec, 14> kSignals = {{
    {"serial", &PlcMap::serial, Table::kHoldingRegister, kSerialRegisters},
    {"operator_id", &PlcMap::operator_id, Table::kHoldingRegister, kOperatorIdRegisters},
    {"shift", &PlcMap::shift, Table::kHoldingRegister, kShiftRegisters},
    {"order_number", &PlcMap::order_number, Table::kHoldingRegister, kOrderNumberRegisters},
    {"variant", &PlcMap::variant, Table::kHoldingRegister, 1},
    {"start", &PlcMap::start, Table::kCoil, 1},
    {"busy", &PlcMap::busy, Table::kDiscreteInput, 1},
    {"done", &PlcMap::done, Table::kDiscreteInput, 1},
    {"ready", &PlcMap::ready, Table::kDiscreteInput, 1},
    {"lockout", &PlcMap::lockout, Table::kDiscreteInput, 1},
    {"result", &PlcMap::result, Table::kInputRegister, 1},
    {"counter", &PlcMap::counter, Table::kInputRegister, 1},
    {"reason", &PlcMap::reason, Table::kInputRegister, 1},
    {"refusal", &PlcMap::refusal, Table::kInputRegister, 1},
}};

}  // namespace

bool PlcMap::IsValid(std::string* why) const {
  for (const SignalSpec& s : kSignals) {
    const int a = this->*(s.member);
    if (a < 0 || a + s.width - 1 > 65535) {
      *why = std::string(s.name) + ": " + TableName(s.table) + " address " + std::to_string(a) +
             (s.width > 1 ? " (" + std::to_string(s.width) + " registers)" : "") +
             " is outside 0..65535";
      return false;
    }
  }
  for (std::size_t i = 0; i < kSignals.size(); ++i) {
    for (std::size_t k = i + 1; k < kSignals.size(); ++k) {
      const SignalSpec& a = kSignals[i];
      const SignalSpec& b = kSignals[k];
      if (a.table != b.table) continue;
      const int a0 = this->*(a.member), b0 = this->*(b.member);
      if (a0 < b0 + b.width && b0 < a0 + a.width) {
        *why = std::string(a.name) + " and " + b.name + " share " + TableName(a.table) +
               " address " + std::to_string(std::max(a0, b0));
        return false;
      }
    }
  }
  return true;
}

PlcMap ParsePlcMap(const nlohmann::json& j, const std::string& path) {
  const io::JsonObject o(j, path);
  PlcMap map;
  std::string known;
  for (const SignalSpec& s : kSignals) {
    known += (known.empty() ? "" : ", ") + std::string(s.name);
    if (!o.Has(s.name)) continue;
    const nlohmann::json& v = o.Raw(s.name);
    if (!v.is_number_integer())
      throw io::ConfigError(o.PathOf(s.name) + ": must be an integer address (got " + v.dump() +
                            ")");
    const std::int64_t a = v.get<std::int64_t>();
    o.Require(a >= 0 && a <= 65535, s.name, "must be an address in [0, 65535]");
    map.*(s.member) = static_cast<int>(a);
  }
  for (const auto& item : j.items()) {
    bool found = false;
    for (const SignalSpec& s : kSignals) found = found || item.key() == s.name;
    if (!found)
      throw io::ConfigError(o.PathOf(item.key()) + ": unknown PLC signal (known: " + known + ")");
  }
  std::string why;
  if (!map.IsValid(&why)) throw io::ConfigError(path + ": " + why);
  return map;
}

PlcResult ToPlcResult(analysis::Outcome outcome) {
  switch (outcome) {
    case analysis::Outcome::kPass:
      return PlcResult::kPass;
    case analysis::Outcome::kFail:
      return PlcResult::kFail;
    case analysis::Outcome::kError:
      return PlcResult::kError;
    case analysis::Outcome::kAborted:
      return PlcResult::kAborted;
  }
  return PlcResult::kError;
}

// No default: a new ReasonCode fails the build here (-Wswitch) until it has a number.
std::uint16_t PlcReasonCode(analysis::ReasonCode code) {
  using analysis::ReasonCode;
  switch (code) {
    case ReasonCode::kLimit:
      return 1;
    case ReasonCode::kMask:
      return 2;
    case ReasonCode::kCondition:
      return 3;
    case ReasonCode::kInterlock:
      return 4;
    case ReasonCode::kFixture:
      return 5;
    case ReasonCode::kAcquisition:
      return 6;
    case ReasonCode::kAnalysis:
      return 7;
    case ReasonCode::kAborted:
      return 8;
    case ReasonCode::kStore:
      return 9;
    case ReasonCode::kLockout:
      return 10;
    case ReasonCode::kRetestLimit:
      return 11;
    case ReasonCode::kSelfCheck:
      return 12;
    case ReasonCode::kInternal:
      return 13;
    case ReasonCode::kLegacy:
      return 14;
    case ReasonCode::kClipped:
      return 15;
  }
  return 13;
}

const char* ToString(PlcRefusal r) {
  switch (r) {
    case PlcRefusal::kNone:
      return "none";
    case PlcRefusal::kBadSerial:
      return "bad_serial";
    case PlcRefusal::kBusy:
      return "busy";
    case PlcRefusal::kStopping:
      return "stopping";
    case PlcRefusal::kBadField:
      return "bad_field";
    case PlcRefusal::kUnknownVariant:
      return "unknown_variant";
    case PlcRefusal::kNoVariant:
      return "no_variant";
    case PlcRefusal::kVariantConflict:
      return "variant_conflict";
  }
  return "?";
}

bool DecodeAscii(const std::uint16_t* registers, int count, std::string* text, std::string* why) {
  text->clear();
  bool ended = false;
  for (int i = 0; i < 2 * count; ++i) {
    const int byte = i % 2 == 0 ? registers[i / 2] >> 8 : registers[i / 2] & 0xFF;
    if (byte == 0) {
      ended = true;
      continue;
    }
    if (ended) {
      *why = "a character follows the NUL at byte " + std::to_string(text->size());
      return false;
    }
    if (byte < 0x20 || byte > 0x7E) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "byte %d is 0x%02X, not printable ASCII", i, byte);
      *why = buf;
      return false;
    }
    text->push_back(static_cast<char>(byte));
  }
  return true;
}

std::vector<std::uint16_t> EncodeAscii(const std::string& text, int count) {
  std::vector<std::uint16_t> out(static_cast<std::size_t>(count), 0);
  for (std::size_t i = 0; i < text.size() && i < 2 * out.size(); ++i) {
    const auto byte = static_cast<std::uint16_t>(static_cast<unsigned char>(text[i]));
    out[i / 2] |= i % 2 == 0 ? static_cast<std::uint16_t>(byte << 8) : byte;
  }
  return out;
}

}  // namespace eol::station::plc
