// Golden units for `eol teach` and `eol detectability`: each file becomes one or more
// analysis::GoldenUnit (named measurement values and, when the file has it, the measured Z).
//   *.csv, *.csv.gz, *.zma  an impedance FRF (or a raw recording CSV, analysed with the recipe's
//                           excitation): analysed as `eol analyze --recipe` does;
//   *.json                  `eol analyze --json` output (one unit: params and fit, no curve),
//                           or `eol export --format json` (an array of records: each record's
//                           measurements and its "impedance" curve). Refused (throws, naming
//                           the record): FAIL, ERROR or ABORTED records, masters (kind other
//                           than "production") and records of another recipe hash than
//                           `recipe`'s. *skipped is left empty (kept for callers' reports).
// Throws std::runtime_error naming the file (and record) that cannot be used.
#pragma once

#include <string>
#include <vector>

#include "analysis/qc/teach.h"
#include "station/recipe.h"

namespace eol::station::cli {

std::vector<analysis::GoldenUnit> ReadGoldenUnits(const std::vector<std::string>& paths,
                                                  const Recipe& recipe,
                                                  std::vector<std::string>* skipped);

}  // namespace eol::station::cli
