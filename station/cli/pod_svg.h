// The POD figure (`--pod-svg FILE` of `eol pod`, `eol production-bench`), drawn with cairo
// (drivers/io/chart.h) as two panels, each with its own x axis; a path ending in .png
// gives a PNG. Top: POD(a) of each sweep (solid), its one-sided lower Wald bound
// (dashed), the a90/95 (likelihood ratio) as a vertical line, the hits (y = 1) and misses
// (y = 0) as markers, a dotted line at POD 0.9. Bottom: the share of each group's units per
// 1 Hz bin of fitted f0 (good units, each defect class) with the taught f0 limits as vertical
// lines.
#pragma once

#include <string>
#include <vector>

#include "analysis/qc/pod.h"

namespace eol::station::cli {

struct PodCurve {
  std::string label;  // "one_magnet", "all_magnets", ...
  analysis::PodSummary fit;
  std::vector<analysis::HitMiss> data;
};

struct F0Group {
  std::string label;
  std::vector<double> f0_hz;
};

struct F0Limit {
  std::string label;  // "f0 lo (taught)"
  double f0_hz = 0.0;
};

// The whole SVG document; `title` goes above the panels. An empty group list leaves the
// bottom panel out.
std::string PodSvg(const std::string& title, const std::vector<PodCurve>& curves,
                   const std::vector<F0Group>& groups, const std::vector<F0Limit>& limits);

// Writes PodSvg to `path`; throws std::runtime_error naming the path when it cannot.
void WritePodSvg(const std::string& path, const std::string& title,
                 const std::vector<PodCurve>& curves, const std::vector<F0Group>& groups,
                 const std::vector<F0Limit>& limits);

}  // namespace eol::station::cli
