// "Nice" axis ticks of the charts (chart.h).
#pragma once

#include <vector>

namespace eol::io {

// "Nice" ticks covering [lo, hi]: steps of 1, 2 or 5 x 10^k, about `target` of them.
std::vector<double> LinearTicks(double lo, double hi, int target = 6);
// Decades (with 2 and 5 between them over at most 3 decades) in [lo, hi], lo > 0; linear
// ticks when fewer than two would fall inside.
std::vector<double> LogTicks(double lo, double hi);

}  // namespace eol::io
