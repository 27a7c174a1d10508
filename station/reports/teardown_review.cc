#include "station/reports/teardown_review.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace eol::station {
namespace {

// P(X >= k) for X ~ Binomial(n, p), summed in log space (n up to millions stays finite).
double UpperTail(std::int64_t k, std::int64_t n, double p) {
  if (k <= 0) return 1.0;
  if (p <= 0.0) return 0.0;
  if (p >= 1.0) return 1.0;
  const double lp = std::log(p), lq = std::log1p(-p);
  const double lgn = std::lgamma(static_cast<double>(n) + 1.0);
  double sum = 0.0;
  for (std::int64_t i = k; i <= n; ++i) {
    const double x = static_cast<double>(i);
    sum += std::exp(lgn - std::lgamma(x + 1.0) - std::lgamma(static_cast<double>(n) - x + 1.0) +
                    x * lp + (static_cast<double>(n) - x) * lq);
  }
  return std::min(1.0, sum);
}

void Sort(ReviewedUnit unit, TeardownReview* r) {
  using analysis::Outcome;
  const bool defective = unit.finding.found == db::TeardownFinding::kDefective;
  if (unit.verdict == Outcome::kFail)
    (defective ? r->hits : r->false_rejects).push_back(std::move(unit));
  else if (unit.verdict == Outcome::kPass)
    (defective ? r->misses : r->confirmed_good).push_back(std::move(unit));
  else
    r->no_verdict.push_back(std::move(unit));
}

nlohmann::json Units(const std::vector<ReviewedUnit>& units) {
  nlohmann::json list = nlohmann::json::array();
  for (const ReviewedUnit& u : units) {
    nlohmann::json j = TeardownJson(u.finding);
    j["verdict"] = analysis::ToString(u.verdict);
    j["tested_at"] = u.tested_at;
    list.push_back(std::move(j));
  }
  return list;
}

}  // namespace

double BinomialLowerBound(std::int64_t successes, std::int64_t trials, double confidence) {
  if (successes < 0 || trials < successes || !(confidence > 0.0 && confidence < 1.0))
    throw std::invalid_argument("binomial bound: needs 0 <= successes (" +
                                std::to_string(successes) + ") <= trials (" +
                                std::to_string(trials) + ") and 0 < confidence < 1");
  if (successes == 0) return 0.0;
  const double alpha = 1.0 - confidence;
  double lo = 0.0, hi = 1.0;  // UpperTail grows with p: find where it reaches alpha
  for (int i = 0; i < 100 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (UpperTail(successes, trials, mid) < alpha ? lo : hi) = mid;
  }
  return lo;
}

TeardownReview ReviewTeardowns(db::Store& store, double confidence) {
  TeardownReview r;
  r.confidence = confidence;
  for (const db::TeardownEntry& e : store.CurrentTeardowns()) {
    ReviewedUnit unit{e, analysis::Outcome::kError, ""};
    if (e.test_id)
      if (const auto t = store.Test(*e.test_id, false)) {
        unit.verdict = t->outcome;
        unit.tested_at = t->started_at;
      }
    Sort(std::move(unit), &r);
  }
  const auto hits = static_cast<std::int64_t>(r.hits.size());
  const auto n = hits + static_cast<std::int64_t>(r.misses.size());
  r.pod = n > 0 ? static_cast<double>(hits) / static_cast<double>(n)
                : std::numeric_limits<double>::quiet_NaN();
  r.pod_lower =
      n > 0 ? BinomialLowerBound(hits, n, confidence) : std::numeric_limits<double>::quiet_NaN();
  return r;
}

nlohmann::json TeardownJson(const db::TeardownEntry& e) {
  return {{"id", e.id},
          {"serial", e.serial},
          {"found", db::ToString(e.found)},
          {"note", e.note},
          {"by", e.by},
          {"at", e.at},
          {"test_id", e.test_id ? nlohmann::json(*e.test_id) : nlohmann::json()},
          {"corrects", e.corrects ? nlohmann::json(*e.corrects) : nlohmann::json()}};
}

nlohmann::json ReviewJson(const TeardownReview& r) {
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; };
  return {{"confirmed_defective", r.hits.size() + r.misses.size()},
          {"hits", Units(r.hits)},
          {"misses", Units(r.misses)},
          {"false_rejects", Units(r.false_rejects)},
          {"confirmed_good", Units(r.confirmed_good)},
          {"no_verdict", Units(r.no_verdict)},
          {"pod", number(r.pod)},
          {"pod_lower", number(r.pod_lower)},
          {"confidence", r.confidence}};
}

}  // namespace eol::station
