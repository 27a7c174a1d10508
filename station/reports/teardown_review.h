// What teardown findings (db/store.h TeardownEntry) say about the station's verdicts:
// `eol teardown`, `eol pod --from-db`, GET /api/units/{serial}/teardown and the unit report
// share it.
//
// Each serial's current finding (its newest entry) is set against the verdict of the test it
// judged (the serial's newest finished test when the finding was recorded):
//   confirmed defective, FAIL   a hit: the station caught the defect
//   confirmed defective, PASS   a miss: an escape
//   not defective, FAIL         a false reject
//   not defective, PASS         a confirmed good unit
//   ERROR or ABORTED            no verdict: neither (counted apart)
// The probability of detection over the confirmed-defective units is hits / (hits + misses)
// with its one-sided Clopper-Pearson (exact binomial) lower bound; without defect sizes it is
// one figure, not a POD curve (analysis/qc/pod.h needs a size per unit).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/qc/measurement.h"
#include "db/store.h"

namespace eol::station {

struct ReviewedUnit {
  db::TeardownEntry finding;
  analysis::Outcome verdict = analysis::Outcome::kError;
  std::string tested_at;  // when the judged test started
};

struct TeardownReview {
  std::vector<ReviewedUnit> hits, misses, false_rejects, confirmed_good, no_verdict;
  double confidence = 0.95;
  // hits / (hits + misses) and its lower bound; NaN without a confirmed-defective unit.
  double pod = 0.0;
  double pod_lower = 0.0;
};

// Reads every current finding and its judged test from `store`.
TeardownReview ReviewTeardowns(db::Store& store, double confidence = 0.95);

// The exact (Clopper-Pearson) one-sided lower confidence bound of a binomial proportion:
// the p at which `successes` or more of `trials` has probability 1 - confidence; 0 for no
// success. Throws std::invalid_argument unless 0 <= successes <= trials and 0 < confidence < 1.
double BinomialLowerBound(std::int64_t successes, std::int64_t trials, double confidence);

nlohmann::json TeardownJson(const db::TeardownEntry& e);
nlohmann::json ReviewJson(const TeardownReview& r);

}  // namespace eol::station
