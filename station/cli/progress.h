// Progress with an ETA for the long commands (production-bench, fit-bench, gap-bench, teach,
// pod, export): one line on stderr, redrawn in place, only when stderr is a terminal; piped or
// redirected, nothing is drawn, so logs and CI output stay clean and stdout (results, JSON) is
// never touched.
//
//   eol production-bench: production units  1234/10000  12%  41 s, ETA 4 min 53 s
//
// The ETA is the phase's elapsed time scaled by what is left of it (the rate so far).
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
  // `command` names the line ("production-bench"). Draws only when `enabled` and stderr is a
  // terminal (isatty(STDERR_FILENO)).
  explicit Progress(std::string command, bool enabled = true);
  ~Progress();  // ends the line, when one was drawn
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  bool drawing() const { return drawing_; }

  // `done` of `total` of `phase` (total < 0: not known, no percentage or ETA); thread-safe.
  // A new phase name restarts the clock of the ETA.
  // Redraws at most 10 times a second, and always at a phase's start, its first finished item
  // (the first ETA) and its end.
  void Update(std::string_view phase, std::int64_t done, std::int64_t total);

  // An analysis::ProgressCallback that calls Update; empty when not drawing (the job then
  // skips the calls). `this` must outlive the job.
  analysis::ProgressCallback Callback();

  // "4 min 53 s", "41 s", "1 h 02 min": the durations of the line.
  static std::string Duration(double seconds);
  // The line for a state; what Update draws (without the terminal control characters).
  static std::string Line(std::string_view command, std::string_view phase, std::int64_t done,
                          std::int64_t total, double elapsed_s);

 private:
  using Clock = std::chrono::steady_clock;
  std::string command_;
  bool drawing_ = false;
  std::mutex mutex_;
  std::string phase_;
  Clock::time_point phase_start_{};
  Clock::time_point last_draw_{};
  bool drawn_ = false;
};

}  // namespace eol::station::cli
