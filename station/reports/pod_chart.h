// Probability of detection from a hits table, and its figure: `eol pod` (--hits FILE,
// --pod-svg FILE), `eol production-bench` and POST /api/pod.svg share it.
//
// The hits table is CSV with a header naming at least the columns size (the defect size a,
// > 0 for a defective unit, 0 for a good one) and hit (1 the unit was rejected, 0 it passed);
// optional columns class (one POD per class, default "all") and f0_hz (the fitted resonance,
// for the figure's distributions; empty when not fitted). Good units (size 0) are part of no
// POD fit; they are drawn in the figure.
//
// The POD figure (`--pod-svg FILE` of `eol pod`, `eol production-bench`), drawn with cairo
// (drivers/io/chart.h) as two panels, each with its own x axis; a path ending in .png
// gives a PNG. Top: POD(a) of each sweep (solid), its one-sided lower Wald bound
// (dashed), the a90/95 (likelihood ratio) as a vertical line, the hits (y = 1) and misses
// (y = 0) as markers, a dotted line at POD 0.9. Bottom: the share of each group's units per
// 1 Hz bin of fitted f0 (good units, each defect class) with the taught f0 limits as vertical
// lines.
#pragma once

#include <istream>
#include <map>
#include <string>
#include <vector>

#include "analysis/qc/pod.h"

namespace eol::station {

struct HitsTable {
  std::map<std::string, std::vector<analysis::HitMiss>> defective;  // by class
  std::map<std::string, std::vector<double>> f0_hz;                 // by class, every unit
};

// Parses a hits CSV; `source` names it in errors. Throws std::runtime_error naming the source
// and line ("hits.csv:3: hit must be 0 or 1"): no header, a missing column, a value that is not
// a number, a size below 0, no defective unit.
HitsTable ParseHits(std::istream& in, const std::string& source);
// The file at `path`; also throws when it cannot be read.
HitsTable ReadHitsFile(const std::string& path);

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

// One fit per class of defective units (analysis/qc/pod.h), in class order.
std::vector<PodCurve> FitPodCurves(const HitsTable& hits, const analysis::PodOptions& options);
// The figure's bottom panel: each class's f0 values.
std::vector<F0Group> F0Groups(const HitsTable& hits);

// The whole SVG document; `title` goes above the panels. An empty group list leaves the
// bottom panel out.
std::string PodSvg(const std::string& title, const std::vector<PodCurve>& curves,
                   const std::vector<F0Group>& groups, const std::vector<F0Limit>& limits);

// Writes PodSvg to `path`; throws std::runtime_error naming the path when it cannot.
void WritePodSvg(const std::string& path, const std::string& title,
                 const std::vector<PodCurve>& curves, const std::vector<F0Group>& groups,
                 const std::vector<F0Limit>& limits);

}  // namespace eol::station
