// Progress of a long analysis job (a bench, a sweep), reported to whoever runs it: the CLI
// draws it on a terminal (station/cli/progress.h), tests count it; analysis itself never
// writes to a terminal.
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>

namespace eol::analysis {

// `done` of `total` items of the stage `phase` ("golden units", "production units", "runs")
// are finished; a job may go through several phases, each counted from 0. Called from the
// job's worker threads, possibly at once: the callee must be thread-safe and quick. An empty
// function gets no reports.
using ProgressCallback =
    std::function<void(std::string_view phase, std::int64_t done, std::int64_t total)>;

}  // namespace eol::analysis
