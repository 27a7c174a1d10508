// The one path every test takes (README.md, Design), as explicit, logged states:
//
//   wait_serial -> check_interlocks -> clamp -> confirm_clamp -> excite -> check_interlocks
//     -> analyse -> judge -> unclamp -> store -> publish -> wait_serial
//   (further phase pairs: after analyse, clamp (pair switch) -> excite -> ... again)
//   (publish_before_release: unclamp waits for the fresh heartbeat only, and publish ->
//    confirm_release -> wait_serial)
//   any fault:  -> safe_state (excitation off first; unclamp only when that is safe)
//               -> store (ERROR or ABORTED with the cause) -> publish
//
// Safety: the excitation relay is closed only after the clamp is confirmed with the pressure
// in the recipe's window, the door closed, the emergency stop healthy and the controller's
// heartbeat alive; a watchdog thread (station/daemon/safety.h) re-checks all of them every
// watchdog_period_ms while the stator is excited, writes the station-alive signal without
// which the controller drops the relay by itself, checks its own loop for stalls, and
// opens the relay the moment anything fails. ERROR is never a PASS,
// and the verdict is published only after the record is durably stored.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "analysis/signal/multisine.h"
#include "db/store.h"
#include "db/test_record.h"
#include "drivers/daq/daq.h"
#include "drivers/fixture/fixture.h"
#include "station/daemon/config.h"
#include "station/daemon/recipe.h"
#include "station/daemon/safety.h"
#include "station/daemon/station_clock.h"
#include "station/daemon/status_board.h"

namespace eol::station {

enum class SeqState {
  kWaitSerial,
  kCheckInterlocks,
  kClamp,
  kConfirmClamp,
  kExcite,
  kAnalyse,
  kJudge,
  kUnclamp,
  kSafeState,
  kStore,
  kPublish,
  kConfirmRelease,  // after publish, with SequencerOptions::publish_before_release only
};
const char* ToString(SeqState s);

struct SequencerOptions {
  std::string station_id = "eol-1";
  // Non-empty on simulators (station/daemon/config.h SimulationReason): every record carries
  // conditions.simulation with this text.
  std::string simulation;
  SafetyOptions safety;
  // Called with the serial before the interlock check (the simulated operator loads a part).
  std::function<void(const std::string& serial)> on_serial;
  // Self-checks with master parts and the lockout (station/daemon/self_check.h); off by default.
  SelfCheckConfig self_check;
  // Off (default): the release is confirmed before the record is stored, and a clamp that
  // does not open makes the test ERROR (a teardown failure, as OpenHTF counts it). On: the
  // record is stored and the verdict published as soon as the release is commanded and the
  // controller's heartbeat after excitation has been seen, while the clamp still moves; the
  // release is confirmed after. A clamp that then does not open is the station's fault, not
  // the motor's: the stored verdict stands, the board says the station is not ready and why,
  // and every serial is refused (nothing clamps or excites) until the clamp reads released.
  bool publish_before_release = false;
  // Every time the sequencer reads or waits for (station/daemon/station_clock.h): its deadlines,
  // polls, trace, record timestamps and the lockout's "now"; the watchdog gets it too.
  // Default: the real clocks.
  StationClock clock;
};

class Sequencer {
 public:
  Sequencer(drivers::Fixture& fixture, drivers::Daq& daq, db::Store& store,
            std::shared_ptr<const Recipe> recipe, StatusBoard& board, SequencerOptions options);
  Sequencer(const Sequencer&) = delete;
  Sequencer& operator=(const Sequencer&) = delete;

  // Runs one test to its end and returns the stored record (with publish_before_release its
  // trace goes on past the stored one: confirm_release). Never throws for station,
  // fixture, acquisition or data faults: they end as ERROR with the cause in reasons.
  db::TestRecord RunTest(const std::string& serial);
  // The same, with who tests it for which order (stored with the record; issue 15).
  db::TestRecord RunTest(const std::string& serial, const db::WorkContext& work);
  // Thread-safe: aborts the test in flight (excitation off, safe state, outcome ABORTED).
  void RequestAbort(const std::string& why);
  SeqState state() const { return state_.load(); }
  // Between tests only (the caller guarantees no RunTest is in progress). `designed` is
  // analysis::DesignMultisine(recipe->excitation), which the caller has already built to
  // validate the recipe before anything was swapped.
  void SetRecipe(std::shared_ptr<const Recipe> recipe, analysis::Excitation designed);
  const Recipe& recipe() const { return *recipe_; }
  // Between tests only: the variant the next tests are of (station/daemon/variants.h), kept in each
  // record's conditions as "variant" (its name) and "variant_by" (how it was picked: "operator",
  // "plc code 2", "prefix 'P10-'", ...). Empty (the default): a station of one recipe, no keys.
  void SetVariant(std::string name, std::string by);
  // Re-reads the self-check state from the store and shows it on the board (GET /api/status).
  // Between tests only; a no-op when self-checks are off.
  void PublishLockout();
  // Times the interlock watchdog cut the excitation since construction. Thread-safe.
  std::uint64_t watchdog_trips() const { return watchdog_trips_.load(); }

 private:
  struct Fault;

  void Enter(db::TestRecord& record, SeqState s, const std::string& detail = "");
  drivers::FixtureInputs ReadInputs(const char* purpose);
  void CheckInterlocks(db::TestRecord& record);
  void ClampAndConfirm(db::TestRecord& record);
  // Plays `periods` periods of the excitation (the first look: transient + averaged periods).
  analysis::Recording ExciteAndRecord(db::TestRecord& record, std::size_t periods);
  // The recipe's phase pairs in one clamping, excited back to back: pair k is analysed on a
  // worker thread while pair k+1 is switched (relay off) and excited. Then, with a
  // "sequential" recipe, a pair whose measurements are undecided after its first look is
  // selected again, excited again and the looks combined (station/daemon/recipe.h
  // SequentialPolicy; the conditions keep "looks", "looks@<pair>" and what was undecided).
  // Last, each pair's curves ("impedance", "model"; "<name>@<pair>" for k > 0) and the first
  // pair's fit summary go into the record. A pair found unusable (its verdict can only be
  // ERROR) stops further excitation once its analysis is known: at most one pair later than
  // a strictly serial order would. With more than one pair the conditions keep
  // "analysis_overlapped_s": the seconds of analysis that ran while a later pair was excited.
  struct MeasuredPair;
  std::vector<MeasuredPair> MeasurePairs(db::TestRecord& record);
  // Switches the fixture's relays to `pair` (relay off) unless it is the one selected.
  void SelectPair(db::TestRecord& record, drivers::PhasePair pair);
  void ExtendWhileUndecided(db::TestRecord& record, drivers::PhasePair pair,
                            const std::string& suffix, analysis::Recording& recording,
                            analysis::ImpedanceAnalysis& a);
  // The verdict of every pair measured, by the one judge (station/daemon/judge.h): the sequencer
  // decides nothing about the motor itself.
  void Judge(db::TestRecord& record, const std::vector<MeasuredPair>& measured);
  // The watchdog's pressure range and longest loop gap into the conditions.
  void RecordWatchdog(db::TestRecord& record, const ExcitationWatchdog& watchdog,
                      double pressure_before_bar);
  // Commands the release and polls until the controller's heartbeat after excitation has
  // been seen and, when `until_released`, the clamp reads released.
  void Unclamp(db::TestRecord& record, bool until_released);
  // publish_before_release: after publish, polls until the clamp reads released; a clamp that
  // does not open within the recipe's release_timeout_s (from the command) sets
  // release_fault_. Never throws.
  void ConfirmRelease(db::TestRecord& record);
  // The release command's time plus the recipe's release_timeout_s.
  std::chrono::steady_clock::time_point ReleaseDeadline() const;
  // While release_fault_ is set: clears it when the clamp now reads released, else refuses
  // the serial (returns true; nothing moves, nothing is stored, as a lockout).
  bool RefusedForReleaseFault(db::TestRecord& record);
  // A serial refused before anything moved (its reasons set): shown as ERROR, never stored.
  void PublishRefusal(db::TestRecord& record);
  void SafeState(db::TestRecord& record);
  void StoreAndPublish(db::TestRecord& record);
  void ThrowIfAborted();

  drivers::Fixture& fixture_;
  drivers::Daq& daq_;
  db::Store& store_;
  std::shared_ptr<const Recipe> recipe_;
  std::string variant_;  // SetVariant
  std::string variant_by_;
  StatusBoard& board_;
  SequencerOptions options_;
  analysis::Excitation excitation_;  // designed from the recipe
  AliveSignal alive_;                // the fixture's station_alive counter
  HeartbeatMonitor heartbeat_;
  // The heartbeat read right after the last excitation ended; Unclamp waits for a newer one.
  std::optional<std::uint32_t> beat_after_excitation_;
  drivers::PhasePair selected_pair_ = drivers::PhasePair::kUV;  // set when clamping
  std::chrono::steady_clock::time_point release_commanded_at_{};
  // Non-empty after a clamp did not open behind a published verdict (publish_before_release).
  std::string release_fault_;

  std::atomic<SeqState> state_{SeqState::kWaitSerial};
  std::atomic<bool> stop_requested_{false};  // sticky: RequestAbort() was called
  std::atomic<std::uint64_t> watchdog_trips_{0};
  std::atomic<bool> abort_{false};  // read by the DAQ: stop playing now (reset per test)
  std::mutex abort_mu_;
  std::string abort_reason_;
  std::chrono::steady_clock::time_point test_start_{};
};

}  // namespace eol::station
