#include "station/daemon/sequencer.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <future>
#include <sstream>
#include <thread>

#include "analysis/fit/fit_json.h"
#include "analysis/impedance_analysis.h"
#include "analysis/text.h"
#include "db/clock.h"
#include "drivers/daq/calibration_file.h"
#include "station/daemon/cycle_time.h"
#include "station/daemon/judge.h"
#include "station/daemon/reason_cause.h"
#include "station/daemon/self_check.h"
#include "station/daemon/version.h"

namespace eol::station {
namespace {

using Clock = std::chrono::steady_clock;
using analysis::Outcome;
using analysis::ReasonCode;
using drivers::FixtureOutput;

using analysis::Fixed;

db::Curve ToCurve(const analysis::Frf& z, const std::string& name) {
  db::Curve c;
  c.name = name;
  c.unit = "ohm";
  c.freq_hz = z.freq_hz;
  for (const auto& v : z.value) {
    c.re.push_back(v.real());
    c.im.push_back(v.imag());
  }
  c.sigma = z.sigma;
  return c;
}

// "fixture heartbeat frozen for N ms": the start of every frozen-heartbeat reason.
std::string FrozenHeartbeat(const HeartbeatMonitor& heartbeat, Clock::time_point now) {
  return "fixture heartbeat frozen for " + Fixed(heartbeat.stale_ms(now), 0) + " ms";
}

}  // namespace

const char* ToString(SeqState s) {
  switch (s) {
    case SeqState::kWaitSerial:
      return "wait_serial";
    case SeqState::kCheckInterlocks:
      return "check_interlocks";
    case SeqState::kClamp:
      return "clamp";
    case SeqState::kConfirmClamp:
      return "confirm_clamp";
    case SeqState::kExcite:
      return "excite";
    case SeqState::kAnalyse:
      return "analyse";
    case SeqState::kJudge:
      return "judge";
    case SeqState::kUnclamp:
      return "unclamp";
    case SeqState::kSafeState:
      return "safe_state";
    case SeqState::kStore:
      return "store";
    case SeqState::kPublish:
      return "publish";
    case SeqState::kConfirmRelease:
      return "confirm_release";
  }
  return "unknown";
}

// A fault that ends the test: ERROR (station fault) or ABORTED (stop requested).
struct Sequencer::Fault {
  analysis::Outcome outcome;
  analysis::Reason reason;
};

// One phase pair measured: its recording is kept for the judge (conditions are computed
// from it). The analysis of its first look ran on a worker from analysis_start to
// analysis_end (the sequencer's clock).
struct Sequencer::MeasuredPair {
  drivers::PhasePair pair;
  analysis::Recording recording;
  analysis::ImpedanceAnalysis analysis;
  Clock::time_point analysis_start{};
  Clock::time_point analysis_end{};
};

Sequencer::Sequencer(drivers::Fixture& fixture, drivers::Daq& daq, db::Store& store,
                     std::shared_ptr<const Recipe> recipe, StatusBoard& board,
                     SequencerOptions options)
    : fixture_(fixture),
      daq_(daq),
      store_(store),
      recipe_(std::move(recipe)),
      board_(board),
      options_(std::move(options)),
      excitation_(analysis::DesignMultisine(recipe_->excitation)),
      alive_(fixture_),
      heartbeat_(
          std::chrono::milliseconds(static_cast<long>(options_.safety.heartbeat_timeout_ms))) {}

void Sequencer::SetRecipe(std::shared_ptr<const Recipe> recipe, analysis::Excitation designed) {
  excitation_ = std::move(designed);
  recipe_ = std::move(recipe);
}

void Sequencer::SetVariant(std::string name, std::string by) {
  variant_ = std::move(name);
  variant_by_ = std::move(by);
}

void Sequencer::RequestAbort(const std::string& why) {
  {
    std::lock_guard<std::mutex> lock(abort_mu_);
    abort_reason_ = why;
  }
  stop_requested_.store(true);
  abort_.store(true);
  // Open the relay now; the sequencer thread will reach its safe state on its own.
  (void)fixture_.Write(FixtureOutput::kExcitationEnable, false);
}

void Sequencer::ThrowIfAborted() {
  if (!stop_requested_.load()) return;
  std::lock_guard<std::mutex> lock(abort_mu_);
  throw Fault{Outcome::kAborted, {ReasonCode::kAborted, "aborted: " + abort_reason_}};
}

void Sequencer::Enter(db::TestRecord& record, SeqState s, const std::string& detail) {
  state_.store(s);
  const double t_ms =
      std::chrono::duration<double, std::milli>(options_.clock.now() - test_start_).count();
  record.trace.push_back({ToString(s), t_ms, detail});
  spdlog::info("[{}] {}{}{}", record.serial, ToString(s), detail.empty() ? "" : ": ", detail);
  board_.OnState(record.serial, s, detail);
}

drivers::FixtureInputs Sequencer::ReadInputs(const char* purpose) {
  auto in = fixture_.ReadInputs();
  if (!in.ok())
    throw Fault{Outcome::kError,
                {ReasonCode::kFixture, std::string(purpose) + ": " + in.status().message(),
                 std::string(cause::kFixtureUnreachable)}};
  return in.value();
}

void Sequencer::CheckInterlocks(db::TestRecord& record) {
  Enter(record, SeqState::kCheckInterlocks);
  // A fixture that failed earlier gets a fresh connection: the station recovers by itself.
  if (fixture_.lifecycle() != drivers::Lifecycle::kInactive &&
      fixture_.lifecycle() != drivers::Lifecycle::kActive) {
    if (const drivers::Status s = fixture_.Connect(); !s.ok()) {
      board_.SetCause(NotReadyCause::kFixtureUnreachable, "fixture unavailable: " + s.message());
      throw Fault{Outcome::kError,
                  {ReasonCode::kFixture, "fixture unavailable: " + s.message(),
                   std::string(cause::kFixtureUnreachable)}};
    }
  }
  if (daq_.lifecycle() != drivers::Lifecycle::kInactive) {
    if (const drivers::Status s = daq_.Connect(); !s.ok()) {
      board_.SetCause(NotReadyCause::kAcquisitionUnavailable,
                      "acquisition unavailable: " + s.message());
      throw Fault{Outcome::kError,
                  {ReasonCode::kAcquisition, "acquisition unavailable: " + s.message(),
                   std::string(cause::kAcquisitionUnavailable)}};
    }
  }
  // The controller latches interlock drops until read (safety.h): the first read clears
  // those from while the station stood idle between tests; from the second on, every drop
  // counts.
  (void)ReadInputs("check interlocks");
  const drivers::FixtureInputs in = ReadInputs("check interlocks");
  // Both drivers answered: their causes are gone (the idle look watches the rest).
  for (NotReadyCause c :
       {NotReadyCause::kFixtureUnreachable, NotReadyCause::kAcquisitionUnavailable,
        NotReadyCause::kDriversNotConnected})
    board_.ClearCause(c);
  if (!heartbeat_.Update(in.heartbeat, options_.clock.now()))
    throw Fault{Outcome::kError,
                {ReasonCode::kInterlock, FrozenHeartbeat(heartbeat_, options_.clock.now()),
                 std::string(cause::kHeartbeatFrozen)}};
  if (const InterlockFinding f = FindInterlockFault(in, *recipe_, false); !f.text.empty())
    throw Fault{Outcome::kError,
                {ReasonCode::kInterlock, "interlock: " + f.text, std::string(f.cause)}};
}

void Sequencer::ClampAndConfirm(db::TestRecord& record) {
  Enter(record, SeqState::kClamp,
        "phase pair " + std::to_string(static_cast<int>(recipe_->phase_pair)));
  if (const drivers::Status s = fixture_.Activate(); !s.ok())
    throw Fault{Outcome::kError,
                {ReasonCode::kFixture, s.message(), std::string(cause::kFixtureCommand)}};
  if (const drivers::Status s = fixture_.SelectPhasePair(recipe_->phase_pair); !s.ok())
    throw Fault{Outcome::kError,
                {ReasonCode::kFixture, s.message(), std::string(cause::kFixtureCommand)}};
  selected_pair_ = recipe_->phase_pair;
  if (const drivers::Status s = fixture_.Write(FixtureOutput::kClampCmd, true); !s.ok())
    throw Fault{Outcome::kError,
                {ReasonCode::kFixture, s.message(), std::string(cause::kFixtureCommand)}};

  Enter(record, SeqState::kConfirmClamp);
  const auto deadline =
      options_.clock.now() + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(recipe_->clamp_timeout_s));
  const auto poll = std::chrono::duration<double, std::milli>(options_.safety.poll_period_ms);
  InterlockFinding why;
  drivers::FixtureInputs in;
  while (true) {
    ThrowIfAborted();
    in = ReadInputs("confirm clamp");
    why = FindInterlockFault(in, *recipe_, true);
    if (why.text.empty()) break;
    if (options_.clock.now() > deadline)
      throw Fault{
          Outcome::kError,
          {ReasonCode::kInterlock,
           "clamp not confirmed within " + Fixed(recipe_->clamp_timeout_s, 1) + " s: " + why.text,
           std::string(why.cause)}};
    options_.clock.Sleep(poll);
  }
  record.conditions.clamp_pressure_bar = in.clamp_pressure_bar;
  record.conditions.phase_pair = static_cast<int>(recipe_->phase_pair);
}

analysis::Recording Sequencer::ExciteAndRecord(db::TestRecord& record, std::size_t periods) {
  // Re-check right before closing the relay: nothing may have changed since confirmation.
  // (Still in the clamp's state: the excite state, and the cycle's excitation step, begin
  // when the stator is about to be excited.)
  const drivers::FixtureInputs in = ReadInputs("interlocks before excitation");
  if (const InterlockFinding f = FindInterlockFault(in, *recipe_, true); !f.text.empty())
    throw Fault{
        Outcome::kError,
        {ReasonCode::kInterlock, "interlock before excitation: " + f.text, std::string(f.cause)}};
  ThrowIfAborted();
  Enter(record, SeqState::kExcite,
        std::to_string(periods) + " periods of " + Fixed(1.0 / excitation_.line_spacing_hz, 3) +
            " s");

  drivers::AcquisitionRequest req;
  req.sample_rate_hz = excitation_.sample_rate_hz;
  req.period_samples = excitation_.period_samples;
  req.excitation_v = excitation_.Repeat(periods);
  db::TestConditions& c = record.conditions;
  c.excitation_peak_v = recipe_->excitation.peak_v;
  c.crest_factor = excitation_.crest_factor;
  c.line_spacing_hz = excitation_.line_spacing_hz;
  c.sample_rate_hz = excitation_.sample_rate_hz;

  std::optional<drivers::StatusOr<analysis::Recording>> result;
  std::optional<std::string> watchdog_fault;
  {
    ExcitationWatchdog watchdog({fixture_, *recipe_, heartbeat_, alive_, options_.safety, abort_,
                                 watchdog_trips_, options_.clock});
    // A fresh station_alive right before the relay closes: the controller closes it only then.
    drivers::Status s = alive_.Fresh();
    if (s.ok()) s = fixture_.Write(FixtureOutput::kExcitationEnable, true);
    if (!s.ok()) {
      (void)fixture_.Write(FixtureOutput::kExcitationEnable, false);
      throw Fault{Outcome::kError,
                  {ReasonCode::kFixture, s.message(), std::string(cause::kFixtureCommand)}};
    }
    result.emplace(daq_.Acquire(req, abort_));
    const auto excitation_off = options_.clock.now();
    (void)fixture_.Write(FixtureOutput::kExcitationEnable, false);
    watchdog.Stop(excitation_off);  // a trip in flight has stored its cause before this returns
    watchdog_fault = watchdog.fault();
    RecordWatchdog(record, watchdog, in.clamp_pressure_bar);
  }
  record.calibration = drivers::CalibrationToJson(daq_.calibration());
  record.calibration["daq"] = daq_.name();
  if (watchdog_fault)
    throw Fault{
        Outcome::kError,
        {ReasonCode::kInterlock, *watchdog_fault, std::string(cause::kLostDuringExcitation)}};
  ThrowIfAborted();
  // The interlocks must still hold now that the relay is open: one that broke between the
  // watchdog's last read and the end of the record makes the recording worthless. The
  // heartbeat is confirmed alive by a fresh beat before the verdict (Unclamp).
  Enter(record, SeqState::kCheckInterlocks, "after excitation");
  const drivers::FixtureInputs after = ReadInputs("interlocks after excitation");
  if (const InterlockFinding f = FindInterlockFault(after, *recipe_, true); !f.text.empty())
    throw Fault{
        Outcome::kError,
        {ReasonCode::kInterlock, "interlock after excitation: " + f.text, std::string(f.cause)}};
  if (!heartbeat_.Update(after.heartbeat, options_.clock.now()))
    throw Fault{Outcome::kError,
                {ReasonCode::kInterlock,
                 FrozenHeartbeat(heartbeat_, options_.clock.now()) + " at the end of excitation",
                 std::string(cause::kHeartbeatFrozen)}};
  beat_after_excitation_ = after.heartbeat;
  if (!result->ok())
    throw Fault{Outcome::kError,
                {ReasonCode::kAcquisition, "acquisition failed: " + result->status().message(),
                 std::string(cause::kAcquisitionFailed)}};
  return std::move(result->value());
}

void Sequencer::SelectPair(db::TestRecord& record, drivers::PhasePair pair) {
  if (pair == selected_pair_) return;
  ThrowIfAborted();
  Enter(record, SeqState::kClamp, "phase pair " + std::to_string(static_cast<int>(pair)));
  if (const drivers::Status s = fixture_.SelectPhasePair(pair); !s.ok())
    throw Fault{
        Outcome::kError,
        {ReasonCode::kFixture, "phase pair " + std::string(PairName(pair)) + ": " + s.message(),
         std::string(cause::kFixtureCommand)}};
  selected_pair_ = pair;
}

std::vector<Sequencer::MeasuredPair> Sequencer::MeasurePairs(db::TestRecord& record) {
  const std::vector<drivers::PhasePair>& pairs = recipe_->phase_pairs;
  // The analysis reads only what the task owns: the recording, the lines, the recipe and
  // the clock.
  auto analyse = [recipe = recipe_, lines = excitation_.lines, now = options_.clock.now](
                     drivers::PhasePair pair, analysis::Recording recording) {
    MeasuredPair m{pair, std::move(recording), {}, now(), {}};
    m.analysis = analysis::AnalyzeRecording(m.recording, lines, recipe->analysis);
    m.analysis_end = now();
    return m;
  };
  // Unwinding on a fault waits for the tasks still running (std::async's futures), at most
  // one analysis: the relay is already off then (ExciteAndRecord opens it before it throws).
  std::vector<std::future<MeasuredPair>> pending;
  std::vector<MeasuredPair> measured;
  std::vector<std::pair<Clock::time_point, Clock::time_point>> excited;
  auto collect_next = [&] { measured.push_back(pending[measured.size()].get()); };
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (k > 0) SelectPair(record, pairs[k]);
    const Clock::time_point t0 = options_.clock.now();
    analysis::Recording recording =
        ExciteAndRecord(record, recipe_->transient_periods + recipe_->periods);
    excited.emplace_back(t0, options_.clock.now());
    pending.push_back(std::async(std::launch::async, analyse, pairs[k], std::move(recording)));
    if (k > 0) {
      // Pair k-1 was analysed while pair k was excited: an unusable pair makes the verdict
      // ERROR whatever follows, so the motor is not excited again.
      collect_next();
      if (!measured.back().analysis.usable) break;
    }
  }
  Enter(record, SeqState::kAnalyse);
  while (measured.size() < pending.size()) collect_next();
  // Seconds of analysis hidden behind a later pair's excitation (0 with one pair).
  double hidden_s = 0.0;
  for (std::size_t k = 0; k < measured.size(); ++k)
    for (std::size_t later = k + 1; later < excited.size(); ++later) {
      const Clock::time_point from = std::max(measured[k].analysis_start, excited[later].first);
      const Clock::time_point to = std::min(measured[k].analysis_end, excited[later].second);
      if (to > from) hidden_s += std::chrono::duration<double>(to - from).count();
    }
  if (pending.size() > 1) record.conditions.analysis_overlapped_s = hidden_s;

  // Extensions only while every pair is usable (else the verdict is ERROR already).
  bool extend = recipe_->sequential.has_value() &&
                std::all_of(measured.begin(), measured.end(),
                            [](const MeasuredPair& m) { return m.analysis.usable; });
  for (std::size_t k = 0; k < measured.size(); ++k) {
    MeasuredPair& m = measured[k];
    const std::string suffix = k == 0 ? "" : std::string("@") + PairName(m.pair);
    if (extend) {
      ExtendWhileUndecided(record, m.pair, suffix, m.recording, m.analysis);
      extend = m.analysis.usable;
    }
    const analysis::ImpedanceAnalysis& a = m.analysis;
    if (a.frf.frf.size() > 0) record.curves.push_back(ToCurve(a.frf.frf, "impedance" + suffix));
    record.conditions.periods_used = a.frf.periods_used;
    if (!a.fit.params.empty()) {
      if (k == 0) record.fit = a.fit;  // analysis/fit/fit_json.h
      record.curves.push_back(ToCurve(a.fit.Model().Evaluate(a.frf.frf.freq_hz), "model" + suffix));
    }
  }
  return measured;
}

void Sequencer::ExtendWhileUndecided(db::TestRecord& record, drivers::PhasePair pair,
                                     const std::string& suffix, analysis::Recording& recording,
                                     analysis::ImpedanceAnalysis& a) {
  const SequentialPolicy& policy = *recipe_->sequential;
  int looks = 1;
  std::vector<std::string> undecided_seen;
  for (int extension = 0; extension < policy.max_extensions && a.usable; ++extension) {
    // The one judge on this pair alone; its conditions are not kept (the verdict's are).
    db::TestConditions scratch = record.conditions;
    const PairMeasurement m{pair, &a, &recording};
    const Judgement j = JudgeUnit(*recipe_, std::span<const PairMeasurement>(&m, 1), scratch);
    const std::vector<std::string> undecided =
        analysis::UndecidedMeasurements(j.measurements, policy.confidence_z);
    if (undecided.empty()) break;
    for (const std::string& name : undecided) undecided_seen.push_back(name + suffix);
    Enter(
        record, SeqState::kAnalyse,
        "undecided at z " + Fixed(policy.confidence_z, 1) + ": " + undecided.front() +
            (undecided.size() > 1 ? " and " + std::to_string(undecided.size() - 1) + " more" : "") +
            "; extending");
    SelectPair(record, pair);  // another pair was excited after this one's first look
    analysis::Recording more = ExciteAndRecord(record, policy.extend_periods);
    Enter(record, SeqState::kAnalyse, "look " + std::to_string(looks + 1));
    analysis::ImpedanceAnalysis b =
        analysis::AnalyzeRecording(more, excitation_.lines, recipe_->analysis);
    recording = std::move(more);  // the conditions are judged on the newest look
    ++looks;
    if (!b.usable) {  // the verdict is then the extension's ERROR, never the first look's
      a = std::move(b);
      break;
    }
    analysis::FrfSummary frf = b.frf;
    frf.frf = analysis::CombineIndependent(a.frf.frf, b.frf.frf);
    a = analysis::AnalyzeImpedance(frf.frf, recipe_->analysis.fit);
    a.frf = std::move(frf);
  }
  db::PairLooks& kept = record.conditions.looks[suffix];
  kept.looks = looks;
  if (!undecided_seen.empty()) kept.undecided = std::move(undecided_seen);
}

// From the check right before the relay closed through the watchdog's reads (a very short
// acquisition may end before the watchdog's first read); the longest gap of its loop, the
// largest over the test's excitations.
void Sequencer::RecordWatchdog(db::TestRecord& record, const ExcitationWatchdog& watchdog,
                               double pressure_before_bar) {
  double p_min = pressure_before_bar, p_max = pressure_before_bar;
  if (const auto range = watchdog.pressure_range()) {
    p_min = std::min(p_min, range->first);
    p_max = std::max(p_max, range->second);
  }
  db::TestConditions& c = record.conditions;
  c.clamp_pressure_min_bar = p_min;
  c.clamp_pressure_max_bar = p_max;
  const double gap = watchdog.max_gap_ms();
  c.watchdog_max_gap_ms = c.watchdog_max_gap_ms ? std::max(*c.watchdog_max_gap_ms, gap) : gap;
}

void Sequencer::Judge(db::TestRecord& record, const std::vector<MeasuredPair>& measured) {
  Enter(record, SeqState::kJudge);
  std::vector<PairMeasurement> pairs;
  for (const MeasuredPair& m : measured) pairs.push_back({m.pair, &m.analysis, &m.recording});
  Judgement j = JudgeUnit(*recipe_, pairs, record.conditions);
  record.outcome = j.outcome;
  record.reasons = std::move(j.reasons);
  record.measurements = std::move(j.measurements);
  for (std::size_t k = 1; k < measured.size(); ++k)
    record.fit["further_pairs"][PairName(measured[k].pair)] = {
        {"outcome", analysis::ToString(j.pair_outcomes[k])}};
}

void Sequencer::Unclamp(db::TestRecord& record, bool until_released) {
  Enter(record, SeqState::kUnclamp, until_released ? "" : "verdict before the clamp is open");
  if (const drivers::Status s = fixture_.Write(FixtureOutput::kClampCmd, false); !s.ok())
    throw Fault{
        Outcome::kError,
        {ReasonCode::kFixture, "unclamp: " + s.message(), std::string(cause::kClampNotReleased)}};
  release_commanded_at_ = options_.clock.now();
  const auto deadline = ReleaseDeadline();
  // Before the verdict is published the controller must prove it was alive at the end of
  // excitation: a heartbeat newer than the one read when the relay opened (a freeze near the
  // end of excitation is shorter than the watchdog's timeout and would pass unseen).
  bool released = !until_released;
  bool fresh_beat = !beat_after_excitation_;
  for (;;) {
    const drivers::FixtureInputs in = ReadInputs("confirm release");
    const auto now = options_.clock.now();
    released = released || in.released;
    fresh_beat = fresh_beat || in.heartbeat != *beat_after_excitation_;
    if (!fresh_beat && !heartbeat_.Update(in.heartbeat, now))
      throw Fault{Outcome::kError,
                  {ReasonCode::kInterlock,
                   FrozenHeartbeat(heartbeat_, now) + " after excitation: its inputs during the "
                                                      "test cannot be trusted",
                   std::string(cause::kHeartbeatFrozen)}};
    if (released && fresh_beat) break;
    if (!released && now > deadline)
      throw Fault{Outcome::kError,
                  {ReasonCode::kFixture,
                   "clamp not released within " + Fixed(recipe_->release_timeout_s, 1) + " s",
                   std::string(cause::kClampNotReleased)}};
    options_.clock.Sleep(std::chrono::duration<double, std::milli>(options_.safety.poll_period_ms));
  }
  if (until_released) (void)fixture_.Deactivate();
}

std::chrono::steady_clock::time_point Sequencer::ReleaseDeadline() const {
  return release_commanded_at_ + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(recipe_->release_timeout_s));
}

void Sequencer::ConfirmRelease(db::TestRecord& record) {
  Enter(record, SeqState::kConfirmRelease);
  const auto deadline = ReleaseDeadline();
  std::string why;
  for (;;) {
    auto in = fixture_.ReadInputs();
    if (in.ok() && in.value().released) break;
    if (options_.clock.now() > deadline) {
      why = in.ok() ? "clamp not released within " + Fixed(recipe_->release_timeout_s, 1) + " s"
                    : "fixture not answering (" + in.status().message() + ")";
      break;
    }
    options_.clock.Sleep(std::chrono::duration<double, std::milli>(options_.safety.poll_period_ms));
  }
  (void)fixture_.Deactivate();
  if (why.empty()) return;
  release_fault_ = why + " after the test of " + record.serial + " (its " +
                   analysis::ToString(record.outcome) +
                   " stands): free the part and check the clamp; tests resume when the clamp "
                   "reads released";
  spdlog::error("[{}] {}", record.serial, release_fault_);
  board_.SetCause(NotReadyCause::kClampNotReleased, release_fault_);
}

void Sequencer::PublishRefusal(db::TestRecord& record) {
  record.outcome = Outcome::kError;
  Enter(record, SeqState::kPublish, "ERROR");
  board_.OnVerdict(record);
  Enter(record, SeqState::kWaitSerial);
}

bool Sequencer::RefusedForReleaseFault(db::TestRecord& record) {
  if (release_fault_.empty()) return false;
  if (auto in = fixture_.ReadInputs(); in.ok() && in.value().released) {
    spdlog::warn("clamp reads released again: {} cleared", release_fault_);
    release_fault_.clear();
    board_.ClearCause(NotReadyCause::kClampNotReleased);
    return false;
  }
  // Refused before anything moves; not a test of the motor, so nothing is stored.
  record.reasons = {{ReasonCode::kFixture, "station stopped: " + release_fault_,
                     std::string(cause::kClampNotReleased)}};
  board_.SetCause(NotReadyCause::kClampNotReleased, release_fault_);
  PublishRefusal(record);
  return true;
}

// Excitation off, then the clamp released when that is safe (station/daemon/safety.h SafeState).
void Sequencer::SafeState(db::TestRecord& record) {
  Enter(record, SeqState::kSafeState, record.reasons.empty() ? "" : record.reasons.front().text);
  // Before the clamp state (refused at check_interlocks) the clamp was never commanded closed:
  // the rotor is not clamped and the reason says only why nothing was commanded.
  const bool clamp_commanded =
      std::any_of(record.trace.begin(), record.trace.end(),
                  [](const db::StateEntry& e) { return e.state == ToString(SeqState::kClamp); });
  for (analysis::Reason& r :
       DriveToSafeState(fixture_, options_.safety, clamp_commanded, options_.clock))
    record.reasons.push_back(std::move(r));
}

void Sequencer::StoreAndPublish(db::TestRecord& record) {
  Enter(record, SeqState::kStore, analysis::ToString(record.outcome));
  record.cycle_s =
      CycleBreakdown({record.trace.begin(), record.trace.end() - 1}, record.trace.back().t_ms);
  record.finished_at = db::UtcIso8601(options_.clock.wall());
  try {
    store_.FinishTest(record);
  } catch (const std::exception& e) {
    // Not stored: never show the motor's verdict; the station failed.
    spdlog::error("[{}] record not stored: {}", record.serial, e.what());
    record.outcome = analysis::Outcome::kError;
    record.reasons.insert(record.reasons.begin(),
                          {ReasonCode::kStore, std::string("record not stored: ") + e.what()});
  }
  Enter(record, SeqState::kPublish, analysis::ToString(record.outcome));
  board_.OnVerdict(record);
  // The fixture's two lamps: green alone PASS, red alone FAIL (reject the rotor), both ERROR
  // or ABORTED (the station could not judge: test again) - distinct without a third output.
  const bool pass = record.outcome == analysis::Outcome::kPass;
  const bool fail = record.outcome == analysis::Outcome::kFail;
  (void)fixture_.Write(FixtureOutput::kLampPass, !fail);
  (void)fixture_.Write(FixtureOutput::kLampFail, !pass);
}

db::TestRecord Sequencer::RunTest(const std::string& serial) {
  return RunTest(serial, db::WorkContext{});
}

db::TestRecord Sequencer::RunTest(const std::string& serial, const db::WorkContext& work) {
  test_start_ = options_.clock.now();
  abort_.store(stop_requested_.load());
  beat_after_excitation_.reset();
  db::TestRecord record;
  record.serial = serial;
  record.work = work;
  record.station_id = options_.station_id;
  record.recipe_id = recipe_->id;
  record.recipe_version = recipe_->version;
  record.recipe_hash = recipe_->hash;
  record.software_version = SoftwareVersion();
  record.started_at = db::UtcIso8601(options_.clock.wall());
  record.outcome = analysis::Outcome::kError;
  if (!options_.simulation.empty()) record.conditions.simulation = options_.simulation;
  if (!variant_.empty()) {
    record.conditions.variant = variant_;
    record.conditions.variant_by = variant_by_;
  }
  Enter(record, SeqState::kWaitSerial, "serial " + serial + " received");
  const std::optional<std::string> master = MasterRole(options_.self_check, serial);
  if (master) record.kind = db::RecordKind::kSelfCheck;

  try {
    if (RefusedForReleaseFault(record)) return record;
    if (options_.self_check.enabled() && !master) {
      const LockoutState lock = EvaluateLockout(options_.self_check, store_, options_.clock.wall());
      if (lock.locked) {
        // Refused before anything moves; not a test of the motor, so nothing is stored.
        record.reasons = {{ReasonCode::kLockout, "station locked out: " + lock.reason}};
        board_.SetLockout(lock.ToJson());
        PublishRefusal(record);
        return record;
      }
    }
    const int max_tests = master ? 0 : recipe_->max_tests_per_serial;  // masters: no limit
    record.max_tests = max_tests;  // "retest 2 of 3": BeginTest sets the attempt
    if (max_tests > 0) {
      const std::size_t earlier = store_.TestsOfSerial(serial).size();
      if (earlier >= static_cast<std::size_t>(max_tests)) {
        // Refused before anything moves; not a test of the motor, so nothing is stored.
        record.reasons = {{ReasonCode::kRetestLimit,
                           "retest limit: serial " + serial + " already has " +
                               std::to_string(earlier) + " tests (recipe allows " +
                               std::to_string(max_tests) + "); send the motor to rework"}};
        PublishRefusal(record);
        return record;
      }
    }
    store_.BeginTest(record);
  } catch (const std::exception& e) {
    // No durable record possible: do not clamp, do not excite.
    record.reasons = {
        {ReasonCode::kStore, std::string("database unavailable, test not started: ") + e.what()}};
    PublishRefusal(record);
    return record;
  }

  bool release_pending = false;
  try {
    ThrowIfAborted();
    if (options_.on_serial) options_.on_serial(serial);
    CheckInterlocks(record);
    ClampAndConfirm(record);
    const std::vector<MeasuredPair> measured = MeasurePairs(record);
    Judge(record, measured);
    Unclamp(record, !options_.publish_before_release);
    // The clamp still moving behind the verdict (after a fault SafeState has unclamped).
    release_pending = options_.publish_before_release;
  } catch (const Fault& f) {
    record.outcome = f.outcome;
    record.reasons.insert(record.reasons.begin(), f.reason);
    SafeState(record);
  } catch (const std::exception& e) {
    record.outcome = Outcome::kError;
    record.reasons.insert(record.reasons.begin(),
                          {ReasonCode::kInternal, std::string("internal error: ") + e.what()});
    SafeState(record);
  }
  if (master) {
    record.self_check = JudgeMasterTest(*master, record);
    record.reasons.push_back(
        {ReasonCode::kSelfCheck,
         std::string(record.self_check["passed"].get<bool>() ? "self-check passed: "
                                                             : "self-check failed: ") +
             record.self_check["detail"].get<std::string>()});
  }
  StoreAndPublish(record);
  // Serial received -> verdict published: the cycle ends where publish does.
  const std::size_t published = record.trace.size();
  if (release_pending) ConfirmRelease(record);
  if (options_.self_check.enabled()) PublishLockout();
  Enter(record, SeqState::kWaitSerial);
  record.cycle_s = CycleBreakdown({record.trace.begin(), record.trace.begin() + published},
                                  record.trace[published].t_ms);
  return record;
}

void Sequencer::PublishLockout() {
  if (!options_.self_check.enabled()) return;
  try {
    board_.SetLockout(EvaluateLockout(options_.self_check, store_, options_.clock.wall()).ToJson());
  } catch (const std::exception& e) {
    board_.SetLockout(
        {{"locked", true}, {"reason", std::string("self-check state unknown: ") + e.what()}});
  }
}

}  // namespace eol::station
