#include "station/reports/gap_report.h"

#include <cmath>
#include <cstdio>
#include <locale>
#include <sstream>

#include "analysis/text.h"

namespace eol::station {
namespace {

using analysis::Printf;
using nlohmann::json;

const char* QuantityName(analysis::Quantity q) {
  return q == analysis::Quantity::kMobility ? "mobility" : "impedance";
}

json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json ParamsValue(const std::vector<analysis::NamedValue>& params) {
  json j = json::object();
  for (const auto& p : params) j[p.name] = Num(p.value);
  return j;
}

json ParamsSigma(const std::vector<analysis::NamedValue>& params) {
  json j = json::object();
  for (const auto& p : params)
    if (std::isfinite(p.sigma)) j[p.name] = p.sigma;
  return j;
}

json FittedParams(const std::vector<analysis::FittedParameter>& params) {
  json j = json::object();
  for (const auto& p : params) j[p.name] = {{"value", Num(p.value)}, {"sigma", Num(p.sigma)}};
  return j;
}

json Bands(const std::vector<analysis::BandGap>& bands) {
  json j = json::array();
  for (const auto& b : bands)
    j.push_back({{"f_lo_hz", b.band.f_lo_hz},
                 {"f_hi_hz", b.band.f_hi_hz},
                 {"significance", Num(b.band.significance)},
                 {"gap_before", Num(b.gap_before)},
                 {"gap_after", Num(b.gap_after)}});
  return j;
}

// Physical offsets (analysis/gap/tolerance.h): {name: {offset, tolerances}}.
json Offsets(const std::vector<analysis::ToleranceDeviation>& offsets) {
  json j = json::object();
  for (const auto& d : offsets)
    j[d.name] = {{"offset", Num(d.offset)}, {"tolerances", Num(d.tolerances)}};
  return j;
}

std::string ParamText(const analysis::NamedValue& p) {
  std::string s = p.name + " = " + Printf("%.5g", p.value);
  if (std::isfinite(p.sigma) && p.sigma > 0.0) s += " +- " + Printf("%.2g", p.sigma);
  return s;
}

}  // namespace

const analysis::RankedEffect* Winner(const analysis::GapSummary& gap) {
  if (gap.winner.empty()) return nullptr;
  for (const auto& r : gap.ranking)
    if (r.effect == gap.effect) return &r;
  return nullptr;
}

namespace {

// The answer: which effect, its rivals, the calibration within and beyond the tolerances.
void AnswerJson(const GapReport& r, json& j) {
  const analysis::GapSummary& g = r.gap;
  j["effect"] = g.effect;
  json names = json::array();
  for (const auto& e : g.winner) names.push_back(analysis::ToString(e.kind));
  j["effects"] = names;
  j["rival"] = g.rival;
  j["rival_score_gap"] = g.rival.empty() ? json(nullptr) : Num(g.rival_score_gap);
  json rivals = json::array();
  for (const auto& x : g.rivals)
    rivals.push_back({{"effect", x.effect}, {"score_gap", Num(x.score_gap)}, {"note", x.note}});
  j["rivals"] = rivals;
  j["calibration_offsets"] = Offsets(g.calibration);
  j["tolerances"] = {{"r", r.tolerances.r},
                     {"l", r.tolerances.l},
                     {"torque_constant", r.tolerances.torque_constant},
                     {"inertia", r.tolerances.inertia},
                     {"stiffness", r.tolerances.stiffness},
                     {"damping", r.tolerances.damping_factor},
                     {"daq_gain", r.tolerances.daq_gain},
                     {"source", r.tolerance_source},
                     {"calibrate", !g.calibration.empty()}};
  j["beyond_tolerance"] = {{"found", g.beyond.found},
                           {"g", Num(g.beyond.g_beyond)},
                           {"cost_gain", Num(g.beyond.cost_gain)},
                           {"offsets", Offsets(g.beyond.offsets)}};
  const analysis::RankedEffect* w = Winner(g);
  j["params"] = w ? ParamsValue(w->params) : json::object();
}

// How large the gap is and where, before and after the answer, with the held-out check.
void GapFiguresJson(const analysis::GapSummary& g, json& j) {
  j["gap_before"] = Num(g.gap_before);
  j["gap_after"] = Num(g.gap_after);
  j["chi2_before"] = Num(g.chi2_before);
  j["chi2_after"] = Num(g.chi2_after);
  j["residuals"] = g.residuals;
  j["noise_z_before"] = Num(g.noise_z_before);
  j["noise_z_after"] = Num(g.noise_z_after);
  j["sigma_scale"] = Num(g.sigma_scale);
  j["heldout"] = {{"gap_before", Num(g.heldout.gap_before)},
                  {"gap_after", Num(g.heldout.gap_after)},
                  {"method", g.heldout.method}};
  j["where"] = Bands(g.where);
  j["where_after"] = Bands(g.where_after);
}

json RankingJson(const std::vector<analysis::RankedEffect>& ranking) {
  json out = json::array();
  for (const auto& e : ranking)
    out.push_back({{"effect", e.effect},
                   {"params", ParamsValue(e.params)},
                   {"params_sigma", ParamsSigma(e.params)},
                   {"score", Num(e.score)},
                   {"bic", Num(e.bic)},
                   {"cost", Num(e.cost)},
                   {"gap_after", Num(e.gap_after)},
                   {"plausible", e.plausible},
                   {"rejected", e.rejected}});
  return out;
}

// Per measured unit: the features of its gap and the refit of the nominal's own parameters.
void FeaturesJson(const GapReport& r, json& j) {
  json features = json::array();
  json refit = json::array();
  for (std::size_t u = 0; u < r.features.size() && u < r.measured.size(); ++u) {
    const auto& f = r.features[u];
    for (const auto& x : f.features)
      features.push_back({{"measurement", r.measured[u].source},
                          {"name", x.name},
                          {"simulated", Num(x.simulated)},
                          {"measured", Num(x.measured)},
                          {"gap", Num(x.gap)},
                          {"sigma", Num(x.sigma)},
                          {"significance", Num(x.significance)}});
    refit.push_back({{"measurement", r.measured[u].source},
                     {"usable", f.usable},
                     {"message", f.message},
                     {"params", FittedParams(f.refit.params)},
                     {"gap_after_refit", Num(f.gap_after_refit)}});
  }
  j["features"] = features;
  j["refit"] = refit;
}

json MotionalJson(const analysis::NominalNetwork& n) {
  if (n.quantity == analysis::Quantity::kMobility)
    return json{{"gain_rad_per_s2_per_a", Num(n.rigid.gain_rad_per_s2_per_a)},
                {"damping_per_s", Num(n.rigid.damping_per_s)}};
  const analysis::MotionalImpedance& m = n.motional;
  return json{{"R_ohm", Num(m.r_ohm)},
              {"L_h", Num(m.l_h)},
              {"Rp_ohm", Num(m.rp_ohm)},
              {"f0_hz", Num(m.f0_hz)},
              {"Q", Num(m.q)}};
}

// How far the gap shrinks: calibration within the tolerances, beyond them, structure.
json SplitJson(const analysis::GapSplit& sp) {
  if (!sp.available) return {{"message", sp.message}};
  json eff = json::array();
  for (const auto& e : sp.effect)
    eff.push_back({{"effect", analysis::ToString(e.kind)}, {"params", e.params}});
  return {{"g_nominal", Num(sp.g_nominal)},
          {"g_within_tolerance", Num(sp.g_within)},
          {"g_beyond_tolerance", Num(sp.g_beyond)},
          {"g_structure", Num(sp.g_structure)},
          {"share_within_tolerance", Num(sp.share_within)},
          {"share_beyond_tolerance", Num(sp.share_beyond)},
          {"share_structure_within_tolerance", Num(sp.share_structure_within)},
          {"share_left_within_tolerance", Num(sp.share_left_within)},
          {"heldout_g_within_tolerance", Num(sp.heldout_g_within)},
          {"heldout_g_beyond_tolerance", Num(sp.heldout_g_beyond)},
          {"heldout_g_structure", Num(sp.heldout_g_structure)},
          {"g_refit", Num(sp.g_refit)},
          {"g_refit_effect", Num(sp.g_refit_effect)},
          {"share_calibration", Num(sp.share_calibration)},
          {"share_structure", Num(sp.share_structure)},
          {"share_left", Num(sp.share_left)},
          {"heldout_g_nominal", Num(sp.heldout_g_nominal)},
          {"heldout_g_refit_effect", Num(sp.heldout_g_refit_effect)},
          {"heldout_method", sp.heldout_method},
          {"refit", MotionalJson(sp.refit)},
          {"refit_effect", MotionalJson(sp.refit_effect)},
          {"effect", eff}};
}

// The inputs: the simulation with its calibration, and each measured unit.
void InputsJson(const GapReport& r, json& j) {
  j["calibration"] = {{"simulation", r.simulation.source},
                      {"kind", r.simulation.kind},
                      {"note", r.simulation.note},
                      {"message", r.calibration.message},
                      {"params", FittedParams(r.calibration.params)},
                      {"misfit_rel_rms", Num(r.calibration.misfit_rel_rms)},
                      {"inertia_kg_m2", Num(r.calibration.nominal.inertia_kg_m2)},
                      {"inertia_source", r.inertia_source}};
  json meas = json::array();
  for (std::size_t u = 0; u < r.measured.size(); ++u) {
    json m = {{"source", r.measured[u].source},
              {"kind", r.measured[u].kind},
              {"note", r.measured[u].note},
              {"lines", r.measured[u].frf.size()},
              {"sigma_estimated", r.measured[u].sigma_estimated}};
    if (u < r.gap.units.size()) {
      m["gap_before"] = Num(r.gap.units[u].gap_before);
      m["gap_after"] = Num(r.gap.units[u].gap_after);
    }
    meas.push_back(m);
  }
  j["measurements"] = meas;
  j["sigma_pool_lines"] = r.sigma_pool;
  j["sigma_dof"] = Num(r.sigma_dof);
}

json PredictionJson(const GapPrediction& pr) {
  const auto& p = pr.prediction;
  json effects = json::array();
  for (const auto& e : p.effects)
    effects.push_back({{"effect", analysis::ToString(e.kind)}, {"params", e.params}});
  return {{"simulation", pr.simulation.source},
          {"usable", p.usable},
          {"f0_simulated_hz", Num(p.f0_simulated_hz)},
          {"f0_predicted_hz", Num(p.f0_predicted_hz)},
          {"sigma_f0_hz", Num(p.sigma_f0_hz)},
          {"q_predicted", Num(p.q_predicted)},
          {"effects", effects},
          {"message", p.message}};
}

constexpr const char* kScoreRule =
    "cost = -2 ln L of the normalised residual (chi2, or the Student t's for sigma on few "
    "degrees of freedom); every fit calibrates the nominal within the design's tolerances, "
    "prior = their -2 ln p; an effect is there when its BIC = cost + prior + p ln(2K) is at "
    "least 10 below the calibrated none's; which one: the lowest score = cost + prior + "
    "Laplace Occam penalty - 2 ln(the effect's prior odds, analysis/gap/diagnosis.h "
    "GapOptions::prior_odds)";

}  // namespace

json GapReportJson(const GapReport& r) {
  const analysis::GapSummary& g = r.gap;
  json j;
  j["quantity"] = QuantityName(r.quantity);
  AnswerJson(r, j);
  GapFiguresJson(g, j);
  j["ranking"] = RankingJson(g.ranking);
  FeaturesJson(r, j);
  j["split"] = SplitJson(g.split);
  InputsJson(r, j);
  if (r.prediction) j["prediction"] = PredictionJson(*r.prediction);
  j["score_rule"] = kScoreRule;
  j["residual_form"] = g.residual_form;
  j["residual_admittance_hz"] = g.admittance_hz;
  j["message"] = g.message;
  return j;
}

namespace {

// The simulation with its nominal, and each measured unit.
void InputsText(const GapReport& r, std::ostream& os) {
  const analysis::GapSummary& g = r.gap;
  os << "eol gap (" << QuantityName(r.quantity) << ", " << r.measured.size() << " measured unit"
     << (r.measured.size() == 1 ? "" : "s") << ")\n";
  os << "simulation   " << r.simulation.source << ": " << r.simulation.note << "\n";
  os << "  nominal    ";
  for (const auto& p : r.calibration.params) os << p.name << " " << Printf("%.5g", p.value) << "  ";
  os << "(misfit " << Printf("%.2g", r.calibration.misfit_rel_rms) << " rms relative";
  if (r.calibration.nominal.inertia_kg_m2 > 0.0)
    os << ", J_r " << Printf("%.4g", r.calibration.nominal.inertia_kg_m2) << " kg m^2"
       << (r.inertia_source == "recipe"
               ? " assumed from the recipe's rotor: the simulation names none (--inertia-kg-m2)"
           : r.inertia_source == "given" ? " given"
                                         : "");
  os << ")\n";
  for (std::size_t u = 0; u < r.measured.size(); ++u) {
    os << "measured     " << r.measured[u].source << ": " << r.measured[u].note << "\n";
    if (u < g.units.size())
      os << "             g " << Printf("%.3f", g.units[u].gap_before) << " -> "
         << Printf("%.3f", g.units[u].gap_after) << "\n";
  }
  if (r.sigma_pool > 0)
    os << "             sigma pooled over +-" << r.sigma_pool << " lines (relative variance)\n";
}

// How large the gap is, where, and the features of the first unit's gap.
void WhereText(const GapReport& r, std::ostream& os) {
  const analysis::GapSummary& g = r.gap;
  os << "\nGAP          g = " << Printf("%.3f", g.gap_before) << " over " << g.residuals / 2
     << " lines (1 = within the noise; noise test z = " << Printf("%.1f", g.noise_z_before)
     << ", sigma scale " << Printf("%.3f", g.sigma_scale) << ")\n";
  if (r.sigma_dof > 0.0)
    os << "             sigma^2 with " << Printf("%.0f", r.sigma_dof)
       << " degrees of freedom per line (F test)\n";
  os << "WHERE        ";
  if (g.where.empty()) os << "no band of the residual is significant";
  os << "\n";
  for (std::size_t i = 0; i < g.where.size(); ++i) {
    const auto& b = g.where[i];
    os << "  " << i + 1 << ". " << Printf("%.1f", b.band.f_lo_hz) << " - "
       << Printf("%.1f", b.band.f_hi_hz) << " Hz   significance "
       << Printf("%.1f", b.band.significance) << "   g " << Printf("%.2f", b.gap_before) << " -> "
       << Printf("%.2f", b.gap_after) << "\n";
  }
  if (!r.features.empty()) {
    os << "  features (refit of the nominal to " << r.measured.front().source
       << " minus simulation):\n";
    const auto& f = r.features.front();
    if (!f.usable) os << "    " << f.message << "\n";
    for (const auto& x : f.features)
      os << "    " << x.name << ": simulated " << Printf("%.5g", x.simulated) << ", measured "
         << Printf("%.5g", x.measured) << ", gap " << Printf("%+.4g", x.gap) << " +- "
         << Printf("%.2g", x.sigma) << " (" << Printf("%.1f", x.significance) << " sigma)\n";
    if (f.usable)
      os << "    a refit of the nominal's own parameters leaves g = "
         << Printf("%.3f", f.gap_after_refit) << " (calibration, not an unmodelled effect)\n";
  }
}

// The answer with its rivals, calibration and parameters.
void WhichText(const GapReport& r, std::ostream& os) {
  const analysis::GapSummary& g = r.gap;
  os << "WHICH        " << g.effect << "\n";
  for (const auto& x : g.rivals)
    os << "  rival      " << x.effect << ", evidence " << Printf("%+.1f", x.score_gap)
       << " against the answer's: " << x.note << "\n";
  if (!g.calibration.empty()) {
    os << "  calibrated within the tolerances:";
    for (const auto& d : g.calibration)
      os << " " << d.name << " " << Printf("%+.1f %%", 100.0 * d.offset) << " ("
         << Printf("%+.1f", d.tolerances) << ")";
    os << "\n";
  }
  if (g.beyond.found) {
    os << "  beyond the tolerances: a calibration with no prior reaches g "
       << Printf("%.3f", g.beyond.g_beyond) << " (-2 ln L " << Printf("%.1f", g.beyond.cost_gain)
       << " lower) with";
    for (const auto& d : g.beyond.offsets)
      if (std::abs(d.tolerances) >= 2.0)
        os << " " << d.name << " " << Printf("%+.1f %%", 100.0 * d.offset) << " ("
           << Printf("%+.1f", d.tolerances) << " tolerances)";
    os << ": " << (g.winner.empty() ? "the finding" : "the alternative to the structure") << "\n";
  }
  if (const analysis::RankedEffect* w = Winner(g)) {
    for (const auto& p : w->params) os << "               " << ParamText(p) << "\n";
  }
}

// Every effect tried with its evidence.
void RankingText(const GapReport& r, std::ostream& os) {
  const analysis::GapSummary& g = r.gap;
  os << "  ranking (score = evidence: cost + Occam - 2 ln prior odds; an effect needs its BIC 10 "
        "below none's; "
     << g.residual_form << " residual):\n";
  int rank = 0;
  for (const auto& e : g.ranking) {
    os << "  " << Printf("%3.0f", ++rank) << ". " << e.effect;
    for (std::size_t pad = e.effect.size(); pad < 36; ++pad) os << ' ';
    os << Printf("%12.1f", e.score) << "  BIC " << Printf("%9.1f", e.bic) << "   g "
       << Printf("%.3f", e.gap_after);
    if (!e.plausible) os << "   rejected: " << e.rejected;
    os << "\n";
  }
}

// How far the gap shrinks: calibration and structure, then the prediction.
void HowFarText(const GapReport& r, std::ostream& os) {
  const analysis::GapSummary& g = r.gap;
  os << "HOW FAR      g " << Printf("%.3f", g.gap_before) << " -> " << Printf("%.3f", g.gap_after)
     << " overall; held out (" << g.heldout.method << ") " << Printf("%.3f", g.heldout.gap_before)
     << " -> " << Printf("%.3f", g.heldout.gap_after) << "\n";
  if (g.split.available) {
    const analysis::GapSplit& sp = g.split;
    auto pct = [](double v) { return std::isfinite(v) ? Printf("%.1f %%", 100.0 * v) : "n/a"; };
    os << "CALIBRATION AND STRUCTURE (share of the excess g^2 - E|r|^2; held out "
       << sp.heldout_method << " in brackets)\n"
       << "  nominal (simulation)                g " << Printf("%.3f", sp.g_nominal) << " ("
       << Printf("%.3f", sp.heldout_g_nominal) << ")\n"
       << "  calibrated within the tolerances    g " << Printf("%.3f", sp.g_within) << " ("
       << Printf("%.3f", sp.heldout_g_within) << ")   closes " << pct(sp.share_within) << "\n"
       << "  + " << (g.winner.empty() ? std::string("no effect") : g.effect) << " (structure)   g "
       << Printf("%.3f", sp.g_structure) << " (" << Printf("%.3f", sp.heldout_g_structure)
       << ")   closes " << pct(sp.share_structure_within) << "; left " << pct(sp.share_left_within)
       << "\n"
       << "  or calibrated beyond them (no prior) g " << Printf("%.3f", sp.g_beyond) << " ("
       << Printf("%.3f", sp.heldout_g_beyond) << ")   closes " << pct(sp.share_beyond)
       << " on top of within\n"
       << "  with no prior from the start:\n"
       << "  refit of the nominal's parameters   g " << Printf("%.3f", sp.g_refit) << "   closes "
       << pct(sp.share_calibration) << " (calibration)\n"
       << "  + " << (g.winner.empty() ? std::string("no effect") : g.effect)
       << " fitted together   g " << Printf("%.3f", sp.g_refit_effect) << "   closes "
       << pct(sp.share_structure) << " (structure); left " << pct(sp.share_left) << "\n"
       << "  held out (" << sp.heldout_method << "): " << Printf("%.3f", sp.heldout_g_nominal)
       << " -> " << Printf("%.3f", sp.heldout_g_refit_effect) << " (calibration + structure)\n";
  } else if (!g.split.message.empty()) {
    os << "CALIBRATION AND STRUCTURE  " << g.split.message << "\n";
  }
  if (!g.where_after.empty())
    os << "  still significant after it: " << g.where_after.size() << " band(s), the first "
       << Printf("%.1f", g.where_after.front().band.f_lo_hz) << " - "
       << Printf("%.1f", g.where_after.front().band.f_hi_hz) << " Hz\n";
  if (r.prediction) {
    os << "PREDICTION   " << r.prediction->simulation.source << ": "
       << r.prediction->prediction.message << "\n";
  }
}

}  // namespace

std::string GapReportText(const GapReport& r) {
  const analysis::GapSummary& g = r.gap;
  std::ostringstream os;
  os.imbue(std::locale::classic());
  InputsText(r, os);
  WhereText(r, os);
  WhichText(r, os);
  RankingText(r, os);
  HowFarText(r, os);
  os << "\n" << g.message << "\n";
  return os.str();
}

}  // namespace eol::station
