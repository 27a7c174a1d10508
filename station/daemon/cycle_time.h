// Where a test's time goes: the sequencer's state trace (db::StateEntry, milliseconds since
// the serial was received) summed per step of the cycle.
//
//   step        sequencer states it covers
//   start       wait_serial (serial received: retest limit, record opened, part loaded)
//   interlocks  check_interlocks (reconnects included; and the re-read after excitation)
//   clamp       clamp, confirm_clamp (command to clamp confirmed with the interlocks
//               re-read before excitation; phase-pair switches)
//   excitation  excite (relay on, acquisition, relay off, watchdog stopped), all pairs
//   analysis    analyse (Z(f), fit): the wait for it; with several phase pairs each pair but
//               the last is analysed while the next is excited, which is not counted here
//               (the record's conditions.analysis_overlapped_s says how much that was)
//   judge       judge
//   unclamp     unclamp (release confirmed, fresh heartbeat); with publish_before_release
//               the release command and the fresh heartbeat only: the release is
//               confirmed after publish (confirm_release), outside the cycle
//   safe_state  safe_state (after a fault)
//   store       store (the durable write)
//   publish     publish (board, event stream, lamps)
//   total       serial received -> the end of the last step summed
// Steps a test did not take are absent. Station overhead = total - clamp - excitation -
// unclamp (what the fixture's motion and the excitation itself do not set).
#pragma once

#include <array>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "db/test_record.h"

namespace eol::station {

inline constexpr std::array<const char*, 10> kCycleSteps = {
    "start", "interlocks", "clamp",      "excitation", "analysis",
    "judge", "unclamp",    "safe_state", "store",      "publish"};

// The step a sequencer state belongs to (table above); "" for an unknown state.
std::string_view CycleStepOf(std::string_view state);

// Seconds per step of trace[0 .. end), each entry lasting until the next one and the last
// until end_ms (the first from 0, the test's clock start); plus "total" = end_ms / 1000. Entries
// with unknown states count in total only.
std::map<std::string, double> CycleBreakdown(const std::vector<db::StateEntry>& trace,
                                             double end_ms);

// Seconds of `step` (0 when the test did not take it).
double CycleStepS(const std::map<std::string, double>& cycle_s, const char* step);

// Station overhead in seconds: total minus clamp, excitation and unclamp (0 when absent).
double StationOverheadS(const std::map<std::string, double>& cycle_s);

}  // namespace eol::station
