// The SciPy side of `eol fit-bench`: the same recordings through the same pipeline written in
// NumPy/SciPy (deploy/bench/fit_pipeline_scipy.py), timed by the script itself, so the C++
// analysis time can be quoted as a ratio. The recordings go to a temporary directory as raw
// float64 files with a JSON manifest (the recipe's period, lines and fit options), removed
// afterwards.
#pragma once

#include <string>
#include <vector>

#include "analysis/bench/fit_bench.h"

namespace eol::station {

struct ScipyPeerResult {
  bool ran = false;  // false: python or scipy missing, or the script failed (see message)
  std::string message;
  std::string scipy_version;
  double ms_mean = 0.0;  // analysis time per test in the peer
  double ms_min = 0.0;
  std::vector<double> f0_hz;  // per recording, in the order of FitBenchResult::kept
};

// Runs `python script manifest` on result.kept with the options' analysis settings. Never
// throws: a missing interpreter, a missing SciPy (exit 2) or a failure gives ran == false.
ScipyPeerResult RunScipyPipelinePeer(const analysis::FitBenchResult& result,
                                     const analysis::FitBenchOptions& options,
                                     const std::string& python, const std::string& script);

}  // namespace eol::station
