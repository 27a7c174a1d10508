// Golden units for `eol teach` and `eol detectability`: each file becomes one or more
// analysis::GoldenUnit (named measurement values and, when the file has it, the measured Z).
//   *.csv, *.csv.gz, *.zma  an impedance FRF (or a raw recording CSV, analysed with the recipe's
//                           excitation): analysed as `eol analyze --recipe` does;
//   *.json                  `eol analyze --json` output (one unit: params and fit, no curve),
//                           or `eol export --format records` (an array of full records: each
//                           record's
//                           measurements and its "impedance" curve). Refused (throws, naming
//                           the record): FAIL, ERROR or ABORTED records, masters (kind other
//                           than "production") and records of another recipe hash than
//                           `recipe`'s. *skipped is left empty (kept for callers' reports).
// With `known_bad` (`eol teach --bad`: units an engineer confirmed defective) a unit's verdict
// may be PASS or FAIL (a torn-down escape passed) and records may be masters (limit masters);
// ERROR and ABORTED records (no measurement to judge) and other recipes are still refused.
// Throws std::runtime_error naming the file (and record) that cannot be used; rows of the
// export schema (`eol export --format json`, no curves) are refused with a hint to
// `--format records`. `progress` (may be empty) sees each file read, phase "golden files" (or
// "known-bad files").
#pragma once

#include <string>
#include <vector>

#include "analysis/progress.h"
#include "analysis/qc/teach.h"
#include "station/daemon/recipe.h"

namespace eol::station::cli {

std::vector<analysis::GoldenUnit> ReadGoldenUnits(const std::vector<std::string>& paths,
                                                  const Recipe& recipe,
                                                  std::vector<std::string>* skipped,
                                                  bool known_bad = false,
                                                  const analysis::ProgressCallback& progress = {});

// Known-bad units from a store's teardown findings (`eol teach --known-bad-from-db`): every
// serial whose current finding is "defective", as measured by the test the finding judged.
// Units whose judged test is ERROR or ABORTED, or of another recipe hash than `recipe`'s, are
// left out and named in *skipped with the reason. Throws std::runtime_error naming the file
// when none is left (or the store cannot be read).
std::vector<analysis::GoldenUnit> ReadKnownBadFromStore(const std::string& db_path,
                                                        const Recipe& recipe,
                                                        std::vector<std::string>* skipped);

}  // namespace eol::station::cli
