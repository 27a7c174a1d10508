// The line PLC's view of the station (the station is the Modbus TCP server, the PLC the
// client): where each handshake signal lives, and what the numbers in it mean.
//
// Default map, unit id 1 (protocol addresses, zero-based; a PLC manual's "00001"/"10001"/
// "30001"/"40001" numbering is these plus one):
//
//   table             addr     signal        meaning
//   holding register  100-115  serial        serial number, ASCII, two characters per register,
//                                            high byte first, NUL padded (at most 32 characters)
//   holding register  116-131  operator_id   who tests, the same encoding (at most 32; NUL: none)
//   holding register  132-139  shift         the shift (at most 16 characters; NUL: none)
//   holding register  140-155  order_number  production order or batch (at most 32)
//   holding register  156      variant       the variant's plc_code (station/daemon/variants.h) of
//   the
//                                            unit to start; 0: none, the serial's part-number
//                                            rules pick it
//   coil              100      start         the PLC sets it to start a test of `serial`; the
//                                            station clears it when it has taken the request
//                                            (accepted or refused, see `refusal`)
//   discrete input    100      busy          a test is waiting or running
//   discrete input    101      done          the test of the last accepted start has ended;
//                                            result and reason are its (valid until the next
//                                            accepted start)
//   discrete input    102      ready         idle and not locked out: a start will be accepted
//   discrete input    103      lockout       self-check lockout: tests end in ERROR (lockout)
//   input register    100      result        0 none, 1 PASS, 2 FAIL, 3 ERROR, 4 ABORTED
//   input register    101      counter       results stored since the station started
//                                            (modulo 2^16); increments when a record is stored
//   input register    102      reason        code of the first reason (PlcReasonCode below;
//                                            0 none)
//   input register    103      refusal       why the last start was refused (PlcRefusal below;
//                                            0 when it was accepted)
//
// The handshake: write `serial` (and operator_id, shift, order_number, which are stored with
// the record; leave them NUL for none; and `variant`, 0 for none), set `start`; wait until `start`
// reads 0; `refusal` 0 means accepted (busy follows at once), otherwise nothing was started and the
// previous result stays readable. Then wait for `done`, read `result`, `reason` and `counter`. A
// start refused by the sequencer itself (lockout, retest limit, database down) ends with done = 1,
// result 3 (ERROR) and its reason, and the counter unchanged: nothing was stored. Tests
// started over HTTP or from the scanner show in busy, result, reason and counter too.
//
// Each address can be moved in the station config's "plc": {"map": {...}}; the tables are
// fixed by what a signal is (the PLC writes coils and holding registers, reads the others):
//
//   "map": {"serial": 0, "operator_id": 16, "shift": 32, "order_number": 40, "start": 0,
//           "busy": 8, "result": 20}
//
// Blocks (serial, operator_id, shift, order_number) may not overlap another signal of their
// table.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/qc/measurement.h"

namespace eol::station::plc {

// Registers of the text blocks: two characters each (station/daemon/test_request.h's lengths).
inline constexpr int kSerialRegisters = 16;
inline constexpr int kOperatorIdRegisters = 16;
inline constexpr int kShiftRegisters = 8;
inline constexpr int kOrderNumberRegisters = 16;

struct PlcMap {
  int serial = 100;        // holding registers serial .. serial + kSerialRegisters - 1
  int operator_id = 116;   // .. + kOperatorIdRegisters - 1
  int shift = 132;         // .. + kShiftRegisters - 1
  int order_number = 140;  // .. + kOrderNumberRegisters - 1
  int variant = 156;       // one holding register
  int start = 100;         // coil
  int busy = 100;          // discrete inputs
  int done = 101;
  int ready = 102;
  int lockout = 103;
  int result = 100;  // input registers
  int counter = 101;
  int reason = 102;
  int refusal = 103;

  // False (with the reason) when an address is outside 0..65535 or two signals of one table
  // share an address.
  bool IsValid(std::string* why) const;
};

// Reads a "map" object at JSON pointer `path` over the defaults. Throws io::ConfigError
// naming the JSON path: an unknown signal (listing the known ones), an address that is not
// an integer in range, or two signals on one address.
PlcMap ParsePlcMap(const nlohmann::json& map, const std::string& path);

// input register `result`.
enum class PlcResult : std::uint16_t { kNone = 0, kPass = 1, kFail = 2, kError = 3, kAborted = 4 };
PlcResult ToPlcResult(analysis::Outcome outcome);

// input register `reason`: the first reason's code (analysis/qc/measurement.h ReasonCode),
// numbered once here for the PLC. Never renumbered; a new ReasonCode gets the next number.
//
//    0  none           (no result yet, or a result without reasons: a PASS)
//    1  limit          a measurement outside its recipe limits (FAIL)
//    2  mask           the impedance curve outside a recipe mask (FAIL)
//    3  condition      a test condition outside its recipe window (ERROR)
//    4  interlock      door, emergency stop, part, clamp or heartbeat (ERROR)
//    5  fixture        the fixture controller failed or did not answer (ERROR)
//    6  acquisition    the DAQ could not record (ERROR)
//    7  analysis       the recording could not be analysed (ERROR)
//    8  aborted        the test was stopped (ABORTED)
//    9  store          the database could not store or begin the record (ERROR)
//   10  lockout        the station refuses tests until a self-check passes (ERROR)
//   11  retest_limit   the serial has used up the recipe's tests (ERROR)
//   12  self_check     the verdict of a master part's check of the station
//   13  internal       a programming error caught at the sequencer's edge (ERROR)
//   14  legacy         a record stored before reasons had codes
//   15  clipped        the recording's voltage or current reached the DAQ's range (ERROR)
std::uint16_t PlcReasonCode(analysis::ReasonCode code);

// input register `refusal`: why a start was refused (nothing was started).
enum class PlcRefusal : std::uint16_t {
  kNone = 0,
  kBadSerial = 1,  // the serial registers hold no valid serial (empty, not printable ASCII,
                   // spaces at either end, a NUL followed by more characters)
  kBusy = 2,       // a test is waiting or running
  kStopping = 3,   // the station is shutting down
  kBadField = 4,   // an operator/shift/order block holds invalid text
  // Variants (station/daemon/variants.h): nothing was started, clamped or excited.
  kUnknownVariant = 5,   // the variant register holds a code no variant has (or the
                         // station runs one recipe and the register is not 0)
  kNoVariant = 6,        // the register is 0 and the serial matches no variant's rule
                         // (or the rules of several)
  kVariantConflict = 7,  // the register's variant is not the one the serial's rule gives
};
const char* ToString(PlcRefusal r);

// Text from registers: two characters per register, high byte first, ending at the first
// NUL; everything after it must be NUL too. False with the reason otherwise, or for a byte
// outside printable ASCII (0x20..0x7E).
bool DecodeAscii(const std::uint16_t* registers, int count, std::string* text, std::string* why);
// The registers for `text` (at most 2 * count characters), NUL padded: the PLC's side.
std::vector<std::uint16_t> EncodeAscii(const std::string& text, int count);

}  // namespace eol::station::plc
