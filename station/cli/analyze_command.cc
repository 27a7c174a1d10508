// `eol analyze --measured FILE`: the station's analysis on a measured FRF or raw recording,
// offline. Reads the file (drivers/io/measured_input.h), estimates Z(f) with sigma for a
// periodic recording, fits the clamped motor (analysis::AnalyzeImpedance / AnalyzeRecording)
// and, with --recipe, judges the unit with the station's own judge (station/daemon/judge.h: limits,
// masks, conditions), so a recording gets the verdict and reasons the station gives it. An FRF
// file has no recording, and a noise recording (Welch) was not excited with the recipe's
// multisine: for both the excitation-level conditions are listed under
// verdict.conditions_not_evaluated instead of being judged.
// A mobility FRF (f_hz,re,im[,sigma]) is fitted with the two-mass model instead (no verdict).
// --plot FILE draws |Z| and Re Z with the fitted model and the recipe's resonance window and
// masks (station/reports/curve_chart.h).
// A raw recording whose voltage or current reached the converter's range (its full scale from
// --voltage-full-scale / --current-full-scale, the CSV's u_full_scale_v / i_full_scale_a
// columns or a WAV's gains; or samples repeated at a rail) is refused before any fit:
// "current clipped at 2 A: ..." (analysis/signal/clipping.h), reason code "clipped".
// Exit codes: 0 a usable analysis (whatever the verdict), 1 the data cannot be analysed
// (reason on stderr and in JSON "error"), 2 usage or file errors.
#include <cmath>
#include <iostream>
#include <locale>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "analysis/fit/fit_json.h"
#include "analysis/impedance_analysis.h"
#include "analysis/model/two_mass.h"
#include "analysis/qc/measurement_json.h"
#include "analysis/qc/measurement_names.h"
#include "analysis/signal/waveform.h"
#include "analysis/signal/welch.h"
#include "analysis/text.h"
#include "db/test_record.h"
#include "drivers/io/file_error.h"
#include "drivers/io/measured_input.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/judge.h"
#include "station/daemon/recipe.h"
#include "station/reports/curve_chart.h"

namespace eol::station::cli {
namespace {

using nlohmann::json;

struct AnalyzeArgs {
  std::string measured;
  std::string recipe;
  bool json = false;
  std::size_t period_samples = 0;
  std::string lines;
  std::string excitation_band;
  double voltage_gain = 0.0;
  double current_gain = 0.0;
  double voltage_full_scale = 0.0;  // > 0: the converter's range of a raw recording
  double current_full_scale = 0.0;
  std::size_t welch_segment = 0;    // > 0: a non-periodic recording, Welch H1
  std::string band;                 // Welch: f_lo,f_hi of the reported lines
  std::string plot;                 // SVG (or .png) of the curve against model and limits
  double clamp_pressure_bar = 0.0;  // > 0: the unit's clamp pressure, as the station reads it
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

double ParseDouble(const std::string& s, const std::string& what) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != s.size() || !std::isfinite(v))
    throw UsageError(what + ": \"" + s + "\" is not a number");
  return v;
}

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep)) out.push_back(item);
  return out;
}

// "200:800,900,1000:1010" -> the bins, increasing and unique.
std::vector<std::size_t> ParseLines(const std::string& spec) {
  std::vector<std::size_t> lines;
  for (const std::string& item : Split(spec, ',')) {
    const std::vector<std::string> range = Split(item, ':');
    if (range.empty() || range.size() > 2) throw UsageError("--lines: bad item \"" + item + "\"");
    const double lo = ParseDouble(range.front(), "--lines");
    const double hi = range.size() == 2 ? ParseDouble(range.back(), "--lines") : lo;
    if (lo < 1 || hi < lo || lo != std::floor(lo) || hi != std::floor(hi))
      throw UsageError("--lines: \"" + item +
                       "\" is not a bin or an increasing range of bins >= 1");
    for (double k = lo; k <= hi; ++k) lines.push_back(static_cast<std::size_t>(k));
  }
  for (std::size_t i = 1; i < lines.size(); ++i)
    if (lines[i] <= lines[i - 1]) throw UsageError("--lines must be increasing and unique");
  if (lines.empty()) throw UsageError("--lines is empty");
  return lines;
}

// The excited bins and period of a periodic recording, from the options or the recipe.
std::vector<std::size_t> SetUpPeriodic(const AnalyzeArgs& a, const Recipe* recipe,
                                       analysis::Recording* rec) {
  const double fs = rec->sample_rate_hz;
  auto whole_period = [&](double spacing_hz, const std::string& from) {
    const double n = fs / spacing_hz;
    if (!(spacing_hz > 0.0) || std::abs(n - std::round(n)) > 1e-6 * n)
      throw UsageError(from + ": a line spacing of " + std::to_string(spacing_hz) +
                       " Hz is not a whole number of samples at " + std::to_string(fs) + " Hz");
    return static_cast<std::size_t>(std::llround(n));
  };
  if (!a.excitation_band.empty()) {
    if (a.period_samples != 0 || !a.lines.empty())
      throw UsageError("give either --excitation-band or --period-samples with --lines");
    const std::vector<std::string> v = Split(a.excitation_band, ',');
    if (v.size() != 3) throw UsageError("--excitation-band needs f_lo,f_hi,spacing (Hz)");
    const double lo = ParseDouble(v[0], "--excitation-band"),
                 hi = ParseDouble(v[1], "--excitation-band");
    const double df = ParseDouble(v[2], "--excitation-band");
    rec->period_samples = whole_period(df, "--excitation-band");
    const std::vector<std::size_t> lines = analysis::BandLines(lo, hi, df);
    if (lines.empty()) throw UsageError("--excitation-band: no line between f_lo and f_hi");
    return lines;
  }
  if (a.period_samples != 0 || !a.lines.empty()) {
    if (a.period_samples == 0 || a.lines.empty())
      throw UsageError("--period-samples and --lines go together");
    rec->period_samples = a.period_samples;
    return ParseLines(a.lines);
  }
  if (recipe) {
    const analysis::MultisineOptions& e = recipe->excitation;
    if (std::abs(fs - e.sample_rate_hz) > 1e-6 * fs)
      throw UsageError("the recording is sampled at " + std::to_string(fs) +
                       " Hz but the recipe's "
                       "excitation at " +
                       std::to_string(e.sample_rate_hz) + " Hz");
    rec->period_samples = whole_period(e.line_spacing_hz, "recipe " + recipe->id);
    return analysis::BandLines(e.f_lo_hz, e.f_hi_hz, e.line_spacing_hz);
  }
  throw UsageError(
      "a raw recording needs its excitation: --recipe, --excitation-band f_lo,f_hi,spacing, or "
      "--period-samples N --lines a:b,...");
}

// Welch H1 options for a non-periodic recording: the band from --band, else the recipe's.
analysis::WelchOptions SetUpWelch(const AnalyzeArgs& a, const Recipe* recipe) {
  if (a.period_samples != 0 || !a.lines.empty() || !a.excitation_band.empty())
    throw UsageError("--welch-segment excludes --period-samples, --lines and --excitation-band");
  analysis::WelchOptions w;
  w.segment_samples = a.welch_segment;
  if (!a.band.empty()) {
    const std::vector<std::string> v = Split(a.band, ',');
    if (v.size() != 2) throw UsageError("--band needs f_lo,f_hi (Hz)");
    w.f_lo_hz = ParseDouble(v[0], "--band");
    w.f_hi_hz = ParseDouble(v[1], "--band");
  } else if (recipe) {
    w.f_lo_hz = recipe->excitation.f_lo_hz;
    w.f_hi_hz = recipe->excitation.f_hi_hz;
  }
  std::string why;
  if (!w.IsValid(&why)) throw UsageError("Welch options: " + why);
  return w;
}

json Param(const analysis::FittedParameter& p) {
  return {{"value", p.value}, {"sigma", p.sigma}, {"unit", p.unit}};
}

using analysis::Fixed;

std::string Sci(double v) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(5);
  os << v;
  return os.str();
}

// The verdict in the measurement field list (analysis/qc/measurement_json.h), plus the
// conditions the judge could not evaluate for a file.
json VerdictJson(const Judgement& v) {
  return {{"outcome", v.outcome},
          {"reasons", v.reasons},
          {"measurements", v.measurements},
          {"conditions_not_evaluated", v.conditions_not_evaluated}};
}

// The station's verdict (station/daemon/judge.h) of the recipe's first phase pair; `recording` is
// null for an FRF file. The conditions the judge evaluates go to out["conditions"].
json JudgeJson(const Recipe& recipe, const analysis::ImpedanceAnalysis& result,
               const analysis::Recording* recording, json& out, Judgement* judgement = nullptr) {
  const PairMeasurement pair{recipe.phase_pair, &result, recording};
  auto conditions = out.value("conditions", db::TestConditions{});  // --clamp-pressure-bar
  Judgement j = JudgeUnit(recipe, std::span<const PairMeasurement>(&pair, 1), conditions);
  out["conditions"] = conditions;
  json v = VerdictJson(j);
  if (judgement) *judgement = std::move(j);
  return v;
}

// Prints the failure on stderr (and as JSON on stdout) and returns the exit code.
int Fail(const AnalyzeArgs& a, json out, int code, const std::string& why) {
  std::cerr << "eol analyze: " << why << std::endl;
  if (a.json) {
    out["error"] = why;
    out["usable"] = false;
    std::cout << out.dump() << std::endl;
  }
  return code;
}

int AnalyzeMobility(const AnalyzeArgs& a, const analysis::Frf& h, json out) {
  const analysis::TwoMassFit fit = analysis::FitTwoMass(h, analysis::TwoMassFitOptions{});
  out["fit"] = {{"model", "two-mass"},
                {"chi2", fit.chi2},
                {"dof", fit.dof},
                {"chi2_per_dof", fit.chi2_per_dof},
                {"termination", fit.termination},
                {"message", fit.message}};
  out["noise_estimated"] = fit.sigma_estimated;
  if (!fit.usable) return Fail(a, out, 1, "two-mass fit not usable: " + fit.message);
  json params = json::object();
  for (const auto& p : fit.params) params[p.name] = Param(p);
  out["params"] = params;
  const analysis::FittedParameter& fr = *fit.Find("f_r_hz");
  const analysis::FittedParameter& far = *fit.Find("f_ar_hz");
  const double zr = fit.response.ZetaR();
  const double q = 1.0 / (2.0 * zr);
  const double q_sigma = q * fit.Find("zeta_ar")->sigma / std::abs(fit.response.zeta_ar);
  out["resonance"] = {{"f_hz", fr.value}, {"f_sigma_hz", fr.sigma}, {"q", q}, {"q_sigma", q_sigma}};
  out["anti_resonance"] = {{"f_hz", far.value}, {"f_sigma_hz", far.sigma}};
  out["usable"] = true;
  if (a.json) {
    std::cout << out.dump() << std::endl;
  } else {
    std::cout << "two-mass fit: anti-resonance " << Fixed(far.value, 3) << " +- " << Sci(far.sigma)
              << " Hz, resonance " << Fixed(fr.value, 3) << " +- " << Sci(fr.sigma) << " Hz\n"
              << fit.message << "\n";
  }
  return 0;
}

// What the command reads: the recipe (optional), the measured file and, for a raw
// recording, its excited lines (periodic) or its Welch options.
struct Inputs {
  std::unique_ptr<Recipe> recipe;
  io::MeasuredInput file;
  std::vector<std::size_t> lines;
  analysis::WelchOptions welch;
};

// Reads the recipe and the file and checks the options against the file's kind. Throws
// UsageError for bad options, io::FileError or io::ConfigError for unreadable files.
void ReadInputs(const AnalyzeArgs& a, Inputs* inputs) {
  if (a.measured.empty()) throw UsageError("--measured FILE is required");
  if (!a.recipe.empty()) inputs->recipe = std::make_unique<Recipe>(LoadRecipe(a.recipe));
  io::MeasuredInput& in = inputs->file;
  in = io::ReadMeasured(a.measured, {a.voltage_gain, a.current_gain});
  const bool recording = in.kind == io::MeasuredKind::kRecording;
  if (!recording && (a.voltage_full_scale > 0.0 || a.current_full_scale > 0.0))
    throw UsageError("--voltage-full-scale and --current-full-scale apply to raw recordings");
  if (a.voltage_full_scale > 0.0) in.recording.voltage_full_scale_v = a.voltage_full_scale;
  if (a.current_full_scale > 0.0) in.recording.current_full_scale_a = a.current_full_scale;
  if (recording && a.welch_segment > 0)
    inputs->welch = SetUpWelch(a, inputs->recipe.get());
  else if (recording)
    inputs->lines = SetUpPeriodic(a, inputs->recipe.get(), &in.recording);
  else if (a.period_samples != 0 || !a.lines.empty() || !a.excitation_band.empty() ||
           a.welch_segment > 0)
    throw UsageError(
        "--period-samples, --lines, --excitation-band and --welch-segment apply to raw "
        "recordings only");
}

// Estimates Z(f) (a recording) and fits it into *result, with the estimate's summary in out.
// Returns the exit code when a Welch estimate is not usable, nothing otherwise.
std::optional<int> EstimateAndFit(const AnalyzeArgs& a, const Inputs& inputs, json& out,
                                  analysis::ImpedanceAnalysis* result) {
  const io::MeasuredInput& in = inputs.file;
  const Recipe* recipe = inputs.recipe.get();
  const analysis::ImpedanceAnalysisOptions options =
      recipe ? recipe->analysis : analysis::ImpedanceAnalysisOptions{};
  if (in.kind == io::MeasuredKind::kFrf) {
    *result = analysis::AnalyzeImpedance(in.frf, options.fit);
  } else if (a.welch_segment > 0) {
    const analysis::WelchSummary w =
        analysis::EstimateWelchFrf(analysis::ChannelPair::Impedance(in.recording), inputs.welch);
    out["frf"] = {{"method", w.frf.method},
                  {"segments", w.segments},
                  {"effective_averages", w.effective_averages},
                  {"message", w.message}};
    if (!w.usable) {
      if (recipe) {
        analysis::ImpedanceAnalysis unusable;
        unusable.message = w.message;
        unusable.frf.clipped = w.clipped;
        out["verdict"] = JudgeJson(*recipe, unusable, nullptr, out);
      }
      return Fail(a, out, 1, "invalid measurement: " + w.message);
    }
    *result = analysis::AnalyzeImpedance(w.frf, options.fit);
    result->frf.message = w.message;
  } else {
    *result = analysis::AnalyzeRecording(in.recording, inputs.lines, options);
  }
  const analysis::Frf& z = result->frf.frf;
  if (in.kind == io::MeasuredKind::kRecording && a.welch_segment == 0)
    out["frf"] = {{"method", z.method},
                  {"periods_used", result->frf.periods_used},
                  {"periods_dropped", result->frf.periods_dropped},
                  {"message", result->frf.message},
                  {"sample_rate_hz", in.recording.sample_rate_hz},
                  {"period_samples", in.recording.period_samples}};
  out["lines"] = z.size();
  out["noise_estimated"] = !z.has_sigma();
  out["fit"] = result->fit;  // analysis/fit/fit_json.h
  if (!z.has_sigma()) out["estimated_sigma_ohm"] = result->fit.estimated_sigma;
  return std::nullopt;
}

// --plot: the curve against the model, with the recipe's window, masks and the verdict's
// reasons. Throws what io::WriteChart throws.
void WritePlot(const AnalyzeArgs& a, const Recipe* recipe,
               const analysis::ImpedanceAnalysis& result, const Judgement& verdict) {
  const analysis::Frf& z = result.frf.frf;
  CurvePlot p;
  p.title = "eol analyze " + a.measured;
  p.freq_hz = z.freq_hz;
  p.measured = z.value;
  p.model_freq_hz = z.freq_hz;
  p.model = result.fit.Model().Evaluate(z.freq_hz).value;
  p.f0_hz = result.fit.Find("f0_hz")->value;
  if (recipe) {
    p.title += " - recipe " + recipe->id + " v" + std::to_string(recipe->version) + ": " +
               analysis::ToString(verdict.outcome);
    for (const analysis::MeasurementSpec& spec : recipe->limits)
      if (spec.name == "resonance_f_hz") p.resonance_window = spec.limit;
    p.masks = recipe->masks;
    for (const analysis::Reason& r : verdict.reasons) p.notes.push_back(r.text);
  } else {
    p.notes.push_back("no --recipe: no limits or masks drawn");
  }
  io::WriteChart(a.plot, CurveChart(p));
}

// The analysis as text on stdout.
void PrintSummary(const AnalyzeArgs& a, const Inputs& inputs,
                  const analysis::ImpedanceAnalysis& result, const Judgement& verdict) {
  const io::MeasuredInput& in = inputs.file;
  const Recipe* recipe = inputs.recipe.get();
  const analysis::Frf& z = result.frf.frf;
  const analysis::FitSummary& fit = result.fit;
  const analysis::FittedParameter& f0 = *fit.Find("f0_hz");
  const analysis::FittedParameter& q = *fit.Find("Q");
  std::cout << a.measured << ": " << in.format << ", " << z.size() << " lines "
            << Fixed(z.freq_hz.front(), 1) << "-" << Fixed(z.freq_hz.back(), 1) << " Hz";
  if (in.kind == io::MeasuredKind::kRecording) std::cout << " (" << result.frf.message << ")";
  std::cout << "\n";
  if (!z.has_sigma())
    std::cout << "noise: the file has no sigma; estimated from the fit residual as "
              << Sci(fit.estimated_sigma) << " ohm per line (complex std): uncertainties below "
              << "assume the model is right\n";
  std::cout << "resonance: f0 = " << Fixed(f0.value, 3) << " +- " << Sci(f0.sigma)
            << " Hz, Q = " << Fixed(q.value, 2) << " +- " << Sci(q.sigma) << "\n";
  for (const auto& p : fit.params)
    std::cout << "  " << p.name << " = " << Sci(p.value) << " +- " << Sci(p.sigma) << " " << p.unit
              << "\n";
  std::cout << "fit: " << fit.model << ", chi2/dof = " << Fixed(fit.chi2_per_dof, 3) << " (dof "
            << fit.dof << "), " << analysis::ToString(fit.termination) << " in " << fit.iterations
            << " iterations\n";
  if (recipe) {
    std::cout << "verdict (" << recipe->id << " v" << recipe->version
              << "): " << analysis::ToString(verdict.outcome) << "\n";
    for (const analysis::Reason& r : verdict.reasons)
      std::cout << "  " << r.text << " [" << analysis::ToString(r.code) << "]\n";
    for (const std::string& c : verdict.conditions_not_evaluated)
      std::cout << "  condition " << c
                << " not evaluated: no recording of the recipe's excitation\n";
  }
}

int RunAnalyze(const AnalyzeArgs& a) {
  json out = {{"file", a.measured}};
  if (a.clamp_pressure_bar > 0.0) {
    db::TestConditions given;
    given.clamp_pressure_bar = a.clamp_pressure_bar;
    out["conditions"] = given;
  }
  Inputs inputs;
  try {
    ReadInputs(a, &inputs);
  } catch (const UsageError& e) {
    return Fail(a, out, 2, std::string("usage: ") + e.what());
  } catch (const std::exception& e) {  // io::FileError, io::ConfigError
    return Fail(a, out, 2, e.what());
  }
  const io::MeasuredInput& in = inputs.file;
  const Recipe* recipe = inputs.recipe.get();
  out["format"] = in.format;
  if (recipe)
    out["recipe"] = {{"id", recipe->id}, {"version", recipe->version}, {"hash", recipe->hash}};
  if (in.kind == io::MeasuredKind::kFrf && in.frf.quantity == analysis::Quantity::kMobility)
    return AnalyzeMobility(a, in.frf, out);

  analysis::ImpedanceAnalysis result;
  if (const std::optional<int> code = EstimateAndFit(a, inputs, out, &result)) return *code;
  const analysis::FitSummary& fit = result.fit;
  // A noise recording (Welch) was not excited with the recipe's multisine: the recipe's
  // excitation-level windows do not apply to it, so it is judged like an FRF file.
  const analysis::Recording* recording =
      in.kind == io::MeasuredKind::kRecording && a.welch_segment == 0 ? &in.recording : nullptr;
  if (!result.usable) {
    if (recipe) out["verdict"] = JudgeJson(*recipe, result, recording, out);
    return Fail(a, out, 1, result.message);
  }
  json params = json::object();
  for (const auto& p : fit.params) params[p.name] = Param(p);
  out["params"] = params;
  const analysis::FittedParameter& f0 = *fit.Find("f0_hz");
  const analysis::FittedParameter& q = *fit.Find("Q");
  out["resonance"] = {
      {"f_hz", f0.value}, {"f_sigma_hz", f0.sigma}, {"q", q.value}, {"q_sigma", q.sigma}};
  Judgement verdict;
  if (recipe) out["verdict"] = JudgeJson(*recipe, result, recording, out, &verdict);
  out["usable"] = true;
  if (!a.plot.empty()) {
    try {
      WritePlot(a, recipe, result, verdict);
    } catch (const std::exception& e) {
      return Fail(a, out, 2, std::string("--plot: ") + e.what());
    }
    out["plot"] = a.plot;
  }
  if (a.json) {
    std::cout << out.dump() << std::endl;
    return 0;
  }
  PrintSummary(a, inputs, result, verdict);
  return 0;
}

}  // namespace

void AddAnalyzeCommand(CLI::App& app) {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "analyze",
      "Analyse a measured frequency response or raw recording offline: estimate Z(f) with its\n"
      "sigma (periodic recordings), fit the clamped motor's resonance by weighted maximum\n"
      "likelihood and, with --recipe, judge it as the station does (limits, masks, conditions).\n"
      "Files: FRF CSV (f_hz,re_ohm,im_ohm[,sigma_ohm]; f_hz,re,im[,sigma] for a mobility, fitted\n"
      "with the two-mass model), .zma (f, |Z|, phase deg), recording CSV (t_s,u_v,i_a), "
      "two-channel\n"
      ".wav (voltage, current; with --voltage-gain and --current-gain). CSV may be gzipped.\n"
      "A recording of random excitation is analysed with Welch H1 (--welch-segment).\n"
      "Exit: 0 analysed, 1 the data cannot be analysed, 2 usage or file error.");
  cmd->add_option("--measured", args->measured, "The measured file");
  cmd->add_option("--recipe", args->recipe,
                  "Recipe JSON: fit options, limits for a verdict, and the excitation of a raw "
                  "recording");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->add_option("--plot", args->plot,
                  "Write |Z| and Re Z, measured and fitted, with the recipe's resonance window\n"
                  "and masks (SVG, or PNG for .png)");
  cmd->add_option("--period-samples", args->period_samples,
                  "Raw recording: samples per excitation period (with --lines)");
  cmd->add_option("--lines", args->lines,
                  "Raw recording: excited DFT bins of one period, e.g. 200:800 or 11,13,17:20");
  cmd->add_option("--excitation-band", args->excitation_band,
                  "Raw recording: f_lo,f_hi,spacing in Hz (every line of the grid in the band)");
  cmd->add_option("--welch-segment", args->welch_segment,
                  "Raw recording of a non-periodic (noise) excitation: Welch H1 with Hann "
                  "segments of N samples, 50 % overlap, sigma from the coherence");
  cmd->add_option("--band", args->band,
                  "Welch: f_lo,f_hi of the lines to fit (default: the recipe's excitation band)");
  cmd->add_option("--clamp-pressure-bar", args->clamp_pressure_bar,
                  "The unit's clamp pressure (bar) as the station read it: the judge's\n"
                  "resonance_f_ref_pressure_hz needs it; kept in the output's conditions\n"
                  "(so eol teach finds it in --json outputs)")
      ->check(Positive());
  cmd->add_option("--voltage-full-scale", args->voltage_full_scale,
                  "Raw recording: the voltage channel's range (V); samples at it are clipped\n"
                  "(default: the CSV's u_full_scale_v column, a WAV's gain; without either,\n"
                  "clipping is found from samples repeated at a rail)")
      ->check(Positive());
  cmd->add_option("--current-full-scale", args->current_full_scale,
                  "Raw recording: the current channel's range (A), as --voltage-full-scale")
      ->check(Positive());
  cmd->add_option("--voltage-gain", args->voltage_gain, "WAV: volts per unit of full scale");
  cmd->add_option("--current-gain", args->current_gain, "WAV: amperes per unit of full scale");
  cmd->callback([args] { RunGuarded("analyze", [&] { return RunAnalyze(*args); }); });
}

}  // namespace eol::station::cli
