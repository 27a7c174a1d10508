#include "station/daemon/conditions.h"

#include <cmath>
#include <cstdio>

#include "analysis/text.h"

namespace eol::station {
namespace {

using analysis::Fixed;

// Empty when inside; otherwise the line naming the value and the window.
std::string Outside(const std::string& what, double v, const analysis::Limit& l,
                    const std::string& unit, int digits) {
  const bool low = l.lo && !(v >= *l.lo);
  const bool high = l.hi && !(v <= *l.hi);
  if (!low && !high) return "";
  return what + " " + Fixed(v, digits) + " " + unit + " outside " +
         (l.lo ? Fixed(*l.lo, digits) : std::string("-inf")) + ".." +
         (l.hi ? Fixed(*l.hi, digits) : std::string("+inf")) + " " + unit;
}

}  // namespace

double WindingTemperatureC(double r_ohm, double r_ref_ohm, double t_ref_c) {
  return t_ref_c + (r_ohm / r_ref_ohm - 1.0) / kCopperAlphaPerK;
}

double RmsAfter(const std::vector<double>& x, std::size_t skip) {
  if (skip >= x.size()) return std::nan("");
  double ss = 0.0;
  for (std::size_t i = skip; i < x.size(); ++i) ss += x[i] * x[i];
  return std::sqrt(ss / static_cast<double>(x.size() - skip));
}

std::vector<std::string> EvaluateConditions(const ConditionWindows& w,
                                            const analysis::Recording* rec,
                                            std::size_t transient_periods,
                                            std::optional<double> r_ohm,
                                            db::TestConditions& conditions,
                                            std::vector<std::string>* not_evaluated) {
  double v_rms = std::nan(""), a_rms = std::nan("");
  if (rec) {
    const std::size_t skip = transient_periods * rec->period_samples;
    v_rms = RmsAfter(rec->voltage_v, skip);
    a_rms = RmsAfter(rec->current_a, skip);
    conditions.excitation_v_rms = v_rms;  // NaN is stored as null
    conditions.excitation_a_rms = a_rms;
  }
  std::vector<std::string> out;
  if (!w.enabled) return out;
  auto check = [&out](const std::string& line) {
    if (!line.empty()) out.push_back(line);
  };
  if (rec) {
    check(Outside("excitation level", v_rms, w.excitation_v_rms, "V rms", 3));
    check(Outside("excitation current", a_rms, w.excitation_a_rms, "A rms", 3));
  } else if (not_evaluated) {
    auto set = [](const analysis::Limit& l) { return l.lo.has_value() || l.hi.has_value(); };
    if (set(w.excitation_v_rms)) not_evaluated->push_back("excitation_v_rms");
    if (set(w.excitation_a_rms)) not_evaluated->push_back("excitation_a_rms");
  }
  if (w.r_ref_ohm > 0.0 && r_ohm && std::isfinite(*r_ohm)) {
    const double t_c = WindingTemperatureC(*r_ohm, w.r_ref_ohm, w.t_ref_c);
    conditions.winding_temperature_c = t_c;
    std::string line = Outside("winding temperature", t_c, w.winding_temperature_c, "degC", 1);
    // No winding gets that hot or cold on a test station: the reference is another motor's.
    if (!line.empty() && (t_c < kImplausibleWindingLoC || t_c > kImplausibleWindingHiC))
      line += " (R " + Fixed(*r_ohm, 4) + " ohm against the recipe's r_ref_ohm " +
              Fixed(w.r_ref_ohm, 4) + " ohm at " + Fixed(w.t_ref_c, 1) +
              " degC: implausible for any winding, the reference is likely another motor's; "
              "eol teach relearns it from golden units)";
    check(line);
  }
  conditions.conditions_in_window = out.empty();
  return out;
}

}  // namespace eol::station
