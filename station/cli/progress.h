// Progress with an ETA for the long commands (production-bench, fit-bench, gap-bench, teach,
// pod, export, db-bench), on stderr only (stdout, results and JSON, is never touched):
//   - stderr a terminal: one line, redrawn in place at most 10 times a second;
//   - stderr piped or redirected (CI, logs, `2>file`): plain lines, no control characters, one
//     every kPlainPeriod (10 s) of a phase and one at its end, so a short job writes one line
//     per phase and a long one shows it is alive.
//
//   eol production-bench: production units  1234/10000  12%  41 s, ETA 4 min 53 s
//
// The ETA is what is left of the phase at the rate measured since the phase's first update
// (items done after it over the time since it): a phase whose first update already counts
// items done (a block copied before the clock started) gets no ETA until one more item is done,
// never "ETA 0 s" halfway.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>

#include "analysis/progress.h"

namespace eol::station::cli {

class Progress {
 public:
  // `command` names the line ("production-bench"). Nothing at all unless `enabled`; a redrawn
  // line when stderr is a terminal (isatty(STDERR_FILENO)), plain lines otherwise.
  explicit Progress(std::string command, bool enabled = true);
  ~Progress();  // ends the line, when one was drawn
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  bool drawing() const { return drawing_; }

  // `done` of `total` of `phase` (total < 0: not known, no percentage or ETA); thread-safe.
  // A new phase name restarts the clock of the ETA.
  // On a terminal: redraws at most 10 times a second, and always at a phase's start, its first
  // finished item (the first ETA) and its end. Plain: every kPlainPeriod and at the end.
  void Update(std::string_view phase, std::int64_t done, std::int64_t total);

  // An analysis::ProgressCallback that calls Update; empty when not drawing (the job then
  // skips the calls). `this` must outlive the job.
  analysis::ProgressCallback Callback();

  // "4 min 53 s", "41 s", "1 h 02 min": the durations of the line.
  static std::string Duration(double seconds);
  // The line for a state; what Update draws (without the terminal control characters).
  // `done0`: the items done at the phase's first update (the ETA's rate counts from there).
  static std::string Line(std::string_view command, std::string_view phase, std::int64_t done,
                          std::int64_t total, double elapsed_s, std::int64_t done0 = 0);

  static constexpr std::chrono::seconds kPlainPeriod{10};

 private:
  using Clock = std::chrono::steady_clock;
  void Draw(std::string_view phase, std::int64_t done, std::int64_t total, Clock::time_point now);

  std::string command_;
  bool drawing_ = false;
  bool terminal_ = false;  // redraw in place; else plain lines
  std::mutex mutex_;
  std::string phase_;
  Clock::time_point phase_start_{};
  std::int64_t phase_done0_ = 0;
  Clock::time_point last_draw_{};
  bool drawn_ = false;
};

}  // namespace eol::station::cli
