#include "station/cli/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace eol::station::cli {

Progress::Progress(std::string command, bool enabled)
    : command_(std::move(command)),
      drawing_(enabled),
      terminal_(enabled && isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (drawn_ && terminal_) std::fputs("\n", stderr);
}

std::string Progress::Duration(double s) {
  if (!std::isfinite(s) || s < 0.0) return "?";
  const auto t = static_cast<long long>(std::llround(s));
  char buf[48];
  if (t < 60)
    std::snprintf(buf, sizeof buf, "%lld s", t);
  else if (t < 3600)
    std::snprintf(buf, sizeof buf, "%lld min %02lld s", t / 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%lld h %02lld min", t / 3600, (t % 3600) / 60);
  return buf;
}

std::string Progress::Line(std::string_view command, std::string_view phase, std::int64_t done,
                           std::int64_t total, double elapsed_s, std::int64_t done0) {
  std::string line =
      "eol " + std::string(command) + ": " + std::string(phase) + "  " + std::to_string(done);
  if (total < 0) return line + "  " + Duration(elapsed_s);  // the total is not known
  line += "/" + std::to_string(total);
  if (total > 0) line += "  " + std::to_string(100 * done / total) + "%";
  line += "  " + Duration(elapsed_s);
  if (done >= total)
    line += ", done";
  else if (done > done0 && elapsed_s > 0.0)  // a rate measured since the phase's first update
    line += ", ETA " + Duration(elapsed_s * static_cast<double>(total - done) /
                                static_cast<double>(done - done0));
  return line;
}

void Progress::Update(std::string_view phase, std::int64_t done, std::int64_t total) {
  if (!drawing_) return;
  const auto now = Clock::now();
  const std::lock_guard<std::mutex> lock(mutex_);
  const bool new_phase = phase != phase_;
  const bool end = total >= 0 && done >= total;
  if (new_phase) {
    if (drawn_ && terminal_) std::fputs("\n", stderr);  // the finished phase's line stays
    phase_ = std::string(phase);
    phase_start_ = now;
    phase_done0_ = done;
    last_draw_ = now;
    if (!terminal_ && !end) return;  // plain: the first line after kPlainPeriod, or the end
  } else if (terminal_) {
    if (done > phase_done0_ + 1 && !end && now - last_draw_ < std::chrono::milliseconds(100))
      return;
  } else if (!end && now - last_draw_ < kPlainPeriod) {
    return;
  }
  Draw(phase, done, total, now);
}

// Under mutex_.
void Progress::Draw(std::string_view phase, std::int64_t done, std::int64_t total,
                    Clock::time_point now) {
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - phase_start_).count();
  const std::string line = Line(command_, phase, done, total, elapsed, phase_done0_);
  if (terminal_)  // \r back to the line's start, \033[K clears what a longer earlier line left
    std::fprintf(stderr, "\r%s\033[K", line.c_str());
  else
    std::fprintf(stderr, "%s\n", line.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

analysis::ProgressCallback Progress::Callback() {
  if (!drawing_) return {};
  return [this](std::string_view phase, std::int64_t done, std::int64_t total) {
    Update(phase, done, total);
  };
}

}  // namespace eol::station::cli
