#include "station/daemon/qc_service.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string_view>

#include "analysis/model/chain_prediction.h"
#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"
#include "db/clock.h"
#include "db/serial_number.h"

namespace eol::station {

using analysis::Fixed;
using nlohmann::json;

json TaughtRecipeJson(const Recipe& r, const analysis::TeachSummary& s,
                      const analysis::TeachOptions& o,
                      const std::vector<std::string>& forced_foreign) {
  Recipe taught = r;
  taught.version = r.version + 1;
  for (analysis::MeasurementSpec& l : taught.limits) {
    for (const analysis::MeasurementSpec& spec : s.limits) {
      if (l.name != spec.name) continue;
      if (spec.limit.lo) l.limit.lo = spec.limit.lo;
      if (spec.limit.hi) l.limit.hi = spec.limit.hi;
      l.limit.marginal = spec.limit.marginal;
    }
  }
  if (!s.masks.empty()) taught.masks = s.masks;
  if (s.bond_index) taught.bond_index = s.bond_index;
  // The pressure-normalised resonance: declared by teach when the golden units' f0 follows
  // their clamp pressure (f0_pressure.h), dropped when it no longer does.
  taught.f0_pressure = s.f0_pressure.definition;
  std::erase_if(taught.limits, [](const analysis::MeasurementSpec& l) {
    return l.name == analysis::names::kResonanceFRefPressureHz;
  });
  for (const analysis::MeasurementSpec& spec : s.limits)
    if (spec.name == analysis::names::kResonanceFRefPressureHz) taught.limits.push_back(spec);
  const WindingReference winding = RelearnWindingReference(r, s);
  if (winding.relearned) taught.conditions.r_ref_ohm = winding.r_ref_ohm;
  const NominalRelearned nominal = RelearnNominal(taught, s);
  if (nominal.relearned) taught.excitation_design->nominal = nominal.nominal;
  std::string note = " Limits v" + std::to_string(r.version + 1) + " taught from " +
                     std::to_string(s.units_used) + " golden units (" +
                     analysis::ToString(o.method) + ", allocation " + o.allocation +
                     ", false-reject target " + json(1.0 - o.coverage).dump() + ", confidence " +
                     json(o.confidence).dump() + ", expected false rejects " +
                     json(s.expected_false_reject).dump() + " [" + json(s.false_reject_lo).dump() +
                     ", " + json(s.false_reject_hi).dump() + "]).";
  if (s.few_units_forced)
    note += " FORCED: " + std::to_string(s.units_used) + " golden units where " +
            std::to_string(s.units_needed) + " are needed.";
  note += " " + winding.note;
  if (!nominal.note.empty()) note += " " + nominal.note;
  std::string approval_note;
  if (!forced_foreign.empty()) {
    note += " FORCED (--force-foreign): golden units of another motor than the recipe expects:";
    for (const std::string& f : forced_foreign) note += " " + f + ";";
    approval_note = "taught from golden units of another motor, forced (--force-foreign)";
  }
  taught.description += note;
  // A proposal until an engineer approves it (recipe.h, RecipeApproval).
  taught.approval = RecipeApproval{"proposed", "eol teach", db::UtcNowIso8601(), approval_note};
  return RecipeToJson(taught);
}

WindingReference RelearnWindingReference(const Recipe& r, const analysis::TeachSummary& s) {
  WindingReference w;
  w.old_r_ref_ohm = w.r_ref_ohm = r.conditions.r_ref_ohm;
  w.t_ref_c = r.conditions.t_ref_c;
  w.golden_c_with_old = std::nan("");
  if (!(r.conditions.r_ref_ohm > 0.0)) {
    w.note = "The recipe has no winding-temperature reference: none relearned.";
    return w;
  }
  const auto it = std::find_if(s.statistics.begin(), s.statistics.end(), [](const auto& t) {
    return t.name == analysis::names::kWindingROhm;
  });
  if (it == s.statistics.end() || !(it->centre > 0.0) || !std::isfinite(it->centre)) {
    w.note = "Winding reference r_ref_ohm " + Fixed(w.old_r_ref_ohm, 4) +
             " ohm kept: no winding_r_ohm limit was taught to relearn it from.";
    return w;
  }
  w.relearned = true;
  w.r_ref_ohm = it->centre;
  w.golden_c_with_old = WindingTemperatureC(it->centre, w.old_r_ref_ohm, w.t_ref_c);
  w.note = "Winding reference r_ref_ohm relearned: " + Fixed(w.old_r_ref_ohm, 4) + " -> " +
           Fixed(w.r_ref_ohm, 4) + " ohm at t_ref_c " + Fixed(w.t_ref_c, 1) +
           " degC (the golden units' winding_r_ohm centre; golden units are taken to be at "
           "t_ref_c).";
  if (w.golden_c_with_old < kImplausibleWindingLoC || w.golden_c_with_old > kImplausibleWindingHiC)
    w.warning = "the recipe's /conditions/winding_temperature_c/r_ref_ohm " +
                Fixed(w.old_r_ref_ohm, 4) + " ohm read its golden units as " +
                Fixed(w.golden_c_with_old, 1) + " degC (outside " +
                Fixed(kImplausibleWindingLoC, 0) + ".." + Fixed(kImplausibleWindingHiC, 0) +
                " degC): it was another motor's reference; the taught recipe has " +
                Fixed(w.r_ref_ohm, 4) + " ohm";
  return w;
}

std::string ExcitationShortOfDesign(const json& taught, const std::string& source) {
  try {
    ParseRecipe(taught, source);
    return "";
  } catch (const std::exception& e) {
    return std::string("the proposal cannot be loaded or approved yet: ") + e.what() +
           "; redesign its excitation for the relearned nominal (eol design-excitation "
           "--recipe <proposal> --out <next>) or state the sigma_f0_hz this motor needs";
  }
}

NominalRelearned RelearnNominal(const Recipe& r, const analysis::TeachSummary& s) {
  NominalRelearned n;
  if (!r.excitation_design) return n;
  n.nominal = r.excitation_design->nominal;
  const std::string disagreement = NominalDisagreement(r, n.nominal);
  if (disagreement.empty()) return n;  // the design's nominal is within the taught limits
  namespace names = analysis::names;
  const std::pair<std::string_view, double*> fields[] = {
      {names::kResonanceFHz, &n.nominal.f0_hz},
      {names::kResonanceQ, &n.nominal.q},
      {names::kWindingROhm, &n.nominal.r_ohm},
      {names::kWindingLH, &n.nominal.l_h},
      {names::kMotionalRpOhm, &n.nominal.rp_ohm}};
  std::string changed;
  for (const auto& [name, value] : fields) {
    const auto it = std::find_if(s.statistics.begin(), s.statistics.end(),
                                 [&](const auto& t) { return t.name == name; });
    if (it == s.statistics.end() || !(it->centre > 0.0) || !std::isfinite(it->centre)) continue;
    changed += std::string(changed.empty() ? "" : ", ") + std::string(name) + " " +
               analysis::Significant(*value, 4) + " -> " + analysis::Significant(it->centre, 4);
    *value = it->centre;
    n.relearned = true;
  }
  if (n.relearned)
    n.note =
        "Excitation-design nominal relearned from the golden units' centres (the design's "
        "disagreed with the taught limits: " +
        disagreement + "): " + changed + ".";
  return n;
}

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// What the recipe expects of `name`: its two-sided limit's centre, else the nominal's value.
std::optional<double> Expected(const Recipe& r, std::string_view name) {
  for (const analysis::MeasurementSpec& l : r.limits)
    if (l.name == name && l.limit.lo && l.limit.hi) return 0.5 * (*l.limit.lo + *l.limit.hi);
  if (!r.excitation_design) return std::nullopt;
  const analysis::MotionalImpedance& n = r.excitation_design->nominal;
  namespace names = analysis::names;
  if (name == names::kResonanceFHz) return n.f0_hz;
  if (name == names::kWindingROhm) return n.r_ohm;
  if (name == names::kWindingLH) return n.l_h;
  if (name == names::kMotionalResidueOhmPerS) return n.ResidueOhmPerS();
  return std::nullopt;
}

}  // namespace

std::vector<std::string> ForeignGoldenUnits(const Recipe& r,
                                            const std::vector<analysis::GoldenUnit>& golden) {
  namespace names = analysis::names;
  std::vector<std::string> out;
  for (std::string_view name : {names::kResonanceFHz, names::kWindingROhm, names::kWindingLH,
                                names::kMotionalResidueOhmPerS}) {
    std::vector<double> v;
    for (const analysis::GoldenUnit& u : golden)
      if (const auto it = u.values.find(std::string(name));
          it != u.values.end() && std::isfinite(it->second) && it->second > 0.0)
        v.push_back(it->second);
    const std::optional<double> expected = Expected(r, name);
    if (v.empty() || !expected || !(*expected > 0.0)) continue;
    const double median = Median(v);
    const std::string unit(names::UnitOf(name));
    std::ostringstream m = analysis::MessageStream();
    m.precision(4);
    m << name << ": the golden units' median " << median << " " << unit;
    if (name == names::kResonanceFHz) {
      const double off = median / *expected - 1.0;
      const auto& fit = r.analysis.fit;
      const bool outside = median <= fit.f0_min_hz || median >= fit.f0_max_hz;
      if (std::abs(off) <= kForeignF0Share && !outside) continue;
      m << " is " << Fixed(100.0 * off, 0) << " % from the recipe's " << *expected << " " << unit
        << " (more than " << Fixed(100.0 * kForeignF0Share, 0) << " %"
        << (outside ? ", at or beyond its analysis f0 window" : "") << ")";
    } else {
      const double factor = std::max(median / *expected, *expected / median);
      if (factor <= kForeignFactor) continue;
      m << " is " << Fixed(factor, 2) << " x " << (median > *expected ? "above" : "below")
        << " the recipe's " << *expected << " " << unit << " (more than a factor "
        << Fixed(kForeignFactor, 1) << ")";
    }
    out.push_back(m.str());
  }
  return out;
}

std::string ForeignGoldenRefusal(const Recipe& recipe, const std::vector<std::string>& foreign,
                                 const std::string& how_to_force) {
  std::string why = "the golden units are not recipe " + recipe.id + "'s motor:";
  for (const std::string& f : foreign) why += " " + f + ";";
  return why + " teach a recipe made for their motor, or " + how_to_force +
         " to teach this one from them (recorded in the taught recipe)";
}

json TeachSummaryJson(const analysis::TeachSummary& s, const analysis::TeachOptions& o) {
  json limits = json::array(), stats = json::array(), masks = json::array();
  const json bond_index = s.bond_index ? BondIndexJson(*s.bond_index) : json(nullptr);
  json f0_pressure = {{"used", s.f0_pressure.definition.has_value()},
                      {"note", s.f0_pressure.note},
                      {"units", s.f0_pressure.units},
                      {"slope", s.f0_pressure.slope},
                      {"slope_sigma", s.f0_pressure.slope_sigma},
                      {"t", s.f0_pressure.t},
                      {"spread_before_pct", s.f0_pressure.spread_before_pct},
                      {"spread_after_pct", s.f0_pressure.spread_after_pct}};
  if (s.f0_pressure.definition)
    f0_pressure["definition"] = F0PressureJson(*s.f0_pressure.definition);
  for (const auto& l : s.limits) limits.push_back(LimitJson(l));
  for (const auto& t : s.statistics)
    stats.push_back({{"name", t.name}, {"centre", t.centre}, {"scale", t.scale}});
  for (const auto& m : s.masks) masks.push_back(MaskJson(m));
  json bounds = json::array();
  for (const auto& b : s.taught_bounds)
    bounds.push_back({{"statistic", b.statistic},
                      {"side", b.lo ? "lo" : "hi"},
                      {"role", b.defect_side ? "defect" : "plausibility"},
                      {"share", b.share},
                      {"k", b.k},
                      {"limit", b.limit}});
  return {{"usable", s.usable},
          {"method", o.method},
          {"allocation", o.allocation},
          {"false_reject_target", 1.0 - o.coverage},
          {"expected_false_reject",
           {{"value", s.expected_false_reject},
            {"lo", s.false_reject_lo},
            {"hi", s.false_reject_hi},
            {"confidence", o.confidence}}},
          {"few_units_forced", s.few_units_forced},
          {"taught_bounds", bounds},
          {"confidence", o.confidence},
          {"coverage", o.coverage},
          {"bounds", s.bounds},
          {"p_bound", s.p_bound},
          {"k", s.k_factor},
          {"units_given", s.units_given},
          {"units_used", s.units_used},
          {"units_needed", s.units_needed},
          {"units_needed_distribution_free", s.units_needed_distribution_free},
          {"rejected", s.rejected},
          {"limits", limits},
          {"masks", masks},
          {"statistics", stats},
          {"bond_index", bond_index},
          {"f0_pressure", f0_pressure},
          {"message", s.message}};
}

analysis::GoldenUnit GoldenFromRecord(const db::TestRecord& r, const std::string& label) {
  analysis::GoldenUnit u;
  u.label = label;
  for (const analysis::Measurement& m : r.measurements) u.values[m.name] = m.value;
  // The clamp pressure read at clamp confirmation (f0_pressure.h).
  if (r.conditions.clamp_pressure_bar)
    u.values[std::string(analysis::names::kClampPressureBar)] = *r.conditions.clamp_pressure_bar;
  for (const db::Curve& c : r.curves) {
    if (c.name != "impedance") continue;
    u.curve.freq_hz = c.freq_hz;
    for (std::size_t k = 0; k < c.re.size() && k < c.im.size(); ++k)
      u.curve.value.emplace_back(c.re[k], c.im[k]);
    u.curve.sigma = c.sigma;
    u.curve.method = "record";
  }
  return u;
}

namespace {

// The latest stored test of each serial as a golden unit; ERROR, ABORTED and untested serials
// are skipped with the reason.
std::vector<analysis::GoldenUnit> StoredGoldenUnits(db::Store& store, std::mutex& store_mu,
                                                    const std::vector<std::string>& serials,
                                                    json* skipped) {
  std::vector<analysis::GoldenUnit> golden;
  std::lock_guard<std::mutex> lock(store_mu);
  for (const std::string& serial : serials) {
    const auto latest = store.LatestOfSerial(serial);
    if (!latest || latest->outcome == analysis::Outcome::kError ||
        latest->outcome == analysis::Outcome::kAborted) {
      skipped->push_back(
          serial + (latest ? ": latest test is " + std::string(analysis::ToString(latest->outcome))
                           : ": no test stored"));
      continue;
    }
    const auto full = store.Test(latest->id, true);
    if (full) golden.push_back(GoldenFromRecord(*full, serial));
  }
  return golden;
}

}  // namespace

TeachResult TeachFromStore(db::Store& store, std::mutex& store_mu, const Recipe& recipe,
                           const std::vector<std::string>& serials,
                           const analysis::TeachOptions& options, bool force_foreign) {
  TeachResult result;
  for (const std::string& serial : serials) {
    std::string why;
    if (!db::ValidSerial(serial, &why)) {
      result.kind = TeachResult::Kind::kBadSerial;
      result.message = "serials: " + json(serial).dump() + ": " + why;
      return result;
    }
  }
  json skipped = json::array();
  const std::vector<analysis::GoldenUnit> golden =
      StoredGoldenUnits(store, store_mu, serials, &skipped);
  const json previous = {{"id", recipe.id}, {"version", recipe.version}, {"hash", recipe.hash}};
  const std::vector<std::string> foreign = ForeignGoldenUnits(recipe, golden);
  if (!foreign.empty() && !force_foreign) {
    result.kind = TeachResult::Kind::kForeignUnits;
    result.message = ForeignGoldenRefusal(recipe, foreign, "\"force_foreign\": true");
    result.report = {{"foreign", foreign}, {"skipped", skipped}, {"previous", previous}};
    return result;
  }
  analysis::TeachOptions for_motor = options;  // the bond index for the recipe's motor
  if (recipe.bond_index) for_motor.bond_residue_to_f0 = recipe.bond_index->residue_to_f0;
  const analysis::TeachSummary summary = analysis::TeachLimits(recipe.limits, golden, for_motor);
  result.report = TeachSummaryJson(summary, options);
  result.report["skipped"] = skipped;
  result.report["previous"] = previous;
  result.report["foreign_forced"] = foreign;
  if (!summary.usable) {
    result.kind = TeachResult::Kind::kNotUsable;
    result.message = summary.message;
    return result;
  }
  const json proposed = TaughtRecipeJson(recipe, summary, options, foreign);
  try {
    const Recipe checked =
        ParseRecipe(proposed, "taught recipe", {.check_excitation_design = false});
    result.report["recipe"] = proposed;
    result.report["recipe_hash"] = checked.hash;
    result.report["excitation_short_of_design"] =
        ExcitationShortOfDesign(proposed, "taught recipe");
  } catch (const std::exception& e) {
    result.kind = TeachResult::Kind::kInvalidRecipe;
    result.message = e.what();
    result.report = json();
  }
  return result;
}

analysis::DetectabilityOptions DetectabilityOptionsFor(const Recipe& r, const io::MotorSpec* motor,
                                                       double k_fixture_nm_per_rad,
                                                       double limit_sigmas,
                                                       double required_sigmas) {
  analysis::DetectabilityOptions o;
  o.excitation = r.excitation;
  o.periods = r.periods;
  o.transient_periods = r.transient_periods;
  o.fit = r.analysis.fit;
  o.required_sigmas = required_sigmas;
  if (motor) {
    o.rotor = motor->rotor;
    o.rotor.soft_magnets.clear();  // the model's good rotor; its classes soften the bonds
    o.r_ohm = motor->r_ohm;
    o.l_h = motor->l_h;
    o.transmission_nm_per_a = motor->TransmissionNmPerA();
  }
  if (k_fixture_nm_per_rad > 0.0) {
    if (!o.rotor.fixture) o.rotor.fixture = analysis::RotorChainParams{}.fixture;
    o.rotor.fixture->stiffness_nm_per_rad = k_fixture_nm_per_rad;
  }
  for (const auto& l : r.limits)
    if (l.limit.lo && l.limit.hi)
      o.unit_spread[l.name] = (*l.limit.hi - *l.limit.lo) / (2.0 * limit_sigmas);
  return o;
}

namespace {

// The f0 the recipe expects (0 when it states none) and where it comes from.
double RecipeF0Hz(const Recipe& r, std::string* source) {
  if (r.excitation_design && r.excitation_design->nominal.f0_hz > 0.0) {
    *source = "its excitation_design nominal";
    return r.excitation_design->nominal.f0_hz;
  }
  for (const auto& l : r.limits)
    if (l.name == analysis::names::kResonanceFHz && l.limit.lo && l.limit.hi) {
      *source = "the middle of its resonance_f_hz limits";
      return 0.5 * (*l.limit.lo + *l.limit.hi);
    }
  return 0.0;
}

}  // namespace

std::string DetectabilityModelMismatch(const Recipe& r, const io::MotorSpec* motor) {
  std::string source;
  const double expected = RecipeF0Hz(r, &source);
  const analysis::DetectabilityOptions o = DetectabilityOptionsFor(r, motor, 0.0, 3.0, 3.0);
  if (!(expected > 0.0) || !o.rotor.fixture) return "";  // IsValid names a missing fixture
  double model = 0.0;
  try {
    model = analysis::PredictGoodMode(o.r_ohm, o.l_h, o.transmission_nm_per_a, o.rotor).f0_hz;
  } catch (const std::exception& e) {
    return std::string("the motor model has no usable mode: ") + e.what();
  }
  if (std::abs(model / expected - 1.0) <= kDetectabilityF0Tolerance) return "";
  return "the motor model's good rotor rings at " + analysis::Significant(model, 4) +
         " Hz in its fixture, but recipe " + r.id + " expects " +
         analysis::Significant(expected, 4) + " Hz (" + source +
         "): the model is another motor (the built-in chain is the ten-pole motor's); give the "
         "recipe's motor JSON (eol detectability --motor recipes/motors/<motor>.json)";
}

json DetectabilityJson(const analysis::DetectabilitySummary& s, const std::string& source,
                       const std::string& spread_source, double required_sigmas) {
  if (!s.usable) return {{"usable", false}, {"error", s.message}};
  json classes = json::array();
  for (const auto& c : s.classes) {
    json ms = json::array();
    for (const auto& m : c.measurements)
      ms.push_back({{"name", m.name},
                    {"good", m.good},
                    {"defect", m.defect},
                    {"sigma", m.sigma},
                    {"spread", m.spread},
                    {"separation", m.separation},
                    {"recommended_limit", m.recommended_limit},
                    {"limit_side", m.limit_is_lo ? "lo" : "hi"},
                    {"miss_probability", m.miss_probability}});
    classes.push_back({{"defect", c.defect},
                       {"fit_usable", c.fit_usable},
                       {"f0_hz", c.f0_hz},
                       {"q", c.q},
                       {"rp_ohm", c.rp_ohm},
                       {"chi2_per_dof", c.chi2_per_dof},
                       {"curve_separation", c.curve_separation},
                       {"best", c.best},
                       {"best_separation", c.best_separation},
                       {"separable", c.separable},
                       {"remedies", c.remedies},
                       {"measurements", ms}});
  }
  return {{"usable", true},
          {"k_fixture_nm_per_rad", s.k_fixture_nm_per_rad},
          {"k_fixture_source", source},
          {"spread_source", spread_source},
          {"required_sigmas", required_sigmas},
          {"f0_good_hz", s.f0_good_hz},
          {"q_good", s.q_good},
          {"chi2_good", s.chi2_good},
          {"dof", s.dof},
          {"classes", classes},
          {"message", s.message}};
}

}  // namespace eol::station
