#include "drivers/io/gap_inputs.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "analysis/gap/noise.h"
#include "analysis/signal/fft.h"
#include "analysis/signal/periodic_frf.h"
#include "drivers/io/frf_files.h"
#include "drivers/io/json_config.h"
#include "drivers/io/motor_json.h"
#include "drivers/io/text_table.h"

namespace eol::io {
namespace {

using analysis::Quantity;

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// The first non-comment line of a (possibly gzipped) text file.
std::string FirstLine(const std::string& path) {
  LineReader in(path);
  std::string line;
  while (in.Next(&line)) {
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    return line;
  }
  throw FileError(path, 0, 0, "empty file");
}

bool IsJson(const std::string& path) {
  const std::string p = Lower(path);
  return EndsWith(p, ".json") || EndsWith(p, ".json.gz");
}
bool IsZma(const std::string& path) { return EndsWith(Lower(path), ".zma"); }

std::string Describe(const analysis::Frf& f) {
  std::ostringstream os;
  os << f.size() << " lines, " << f.freq_hz.front() << "-" << f.freq_hz.back() << " Hz";
  return os.str();
}

void CheckQuantity(const analysis::Frf& f, Quantity want, const std::string& path) {
  if (f.quantity != want)
    throw FileError(path, 0, 0,
                    std::string("holds a ") + analysis::ToString(f.quantity) +
                        ", but --quantity is " + analysis::ToString(want) +
                        " (FRF CSV headers: f_hz,re_ohm,im_ohm for "
                        "an impedance, f_hz,re,im for a mobility)");
}

GapInput ReadFrfFile(const std::string& path, Quantity quantity) {
  GapInput in;
  in.source = path;
  if (IsZma(path)) {
    in.kind = "zma";
    in.frf = ReadZma(path);
  } else {
    in.kind = "frf-csv";
    in.frf = ReadFrfCsv(path, &in.sigma_dof);
  }
  CheckQuantity(in.frf, quantity, path);
  in.note = in.kind + ", " + Describe(in.frf);
  if (in.sigma_dof > 0.0) {
    std::ostringstream os;
    os << "; sigma^2 on " << in.sigma_dof << " degrees of freedom (sigma_dof column)";
    in.note += os.str();
  }
  return in;
}

// Excited lines (bins) of a period of n samples at fs.
std::vector<std::size_t> LinesFromFile(const std::string& path, double line_spacing_hz) {
  LineReader in(path);
  std::vector<std::size_t> lines;
  std::string line;
  while (in.Next(&line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    const double f = ParseNumber(line, path, in.line_number(), 1, "excited line (Hz)");
    const double bin = f / line_spacing_hz;
    if (!(bin >= 1.0) || std::abs(bin - std::round(bin)) > 1e-6)
      throw FileError(path, in.line_number(), 1,
                      "excited line " + std::to_string(f) +
                          " Hz is not a positive multiple of "
                          "the line spacing " +
                          std::to_string(line_spacing_hz) + " Hz");
    lines.push_back(static_cast<std::size_t>(std::llround(bin)));
  }
  if (lines.empty()) throw FileError(path, 0, 0, "no excited lines");
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  return lines;
}

std::size_t DetectPeriod(const std::vector<double>& x, const std::string& path) {
  const std::size_t n = x.size();
  double energy = 0.0;
  for (double v : x) energy += v * v;
  std::vector<std::pair<std::size_t, double>> candidates;
  double best = 1e300;
  for (std::size_t p = 8; p <= n / 3; ++p) {
    if (n % p != 0) continue;
    double d = 0.0;
    for (std::size_t t = p; t < n; ++t) d += (x[t] - x[t - p]) * (x[t] - x[t - p]);
    const double rel = d / (energy * static_cast<double>(n - p) / static_cast<double>(n));
    candidates.push_back({p, rel});
    best = std::min(best, rel);
  }
  for (const auto& [p, rel] : candidates)
    if (rel < 0.1 && rel <= 2.0 * best + 1e-12) return p;
  throw FileError(path, 0, 0,
                  "cannot find the excitation period (no whole divisor of the record repeats); "
                  "give it with --period-s");
}

GapInput ReadRecording(const std::string& path, const GapInputOptions& o) {
  const CsvTable t = ReadCsvTable(path);
  const bool mobility = o.quantity == Quantity::kMobility;
  const std::string in_name = !o.input_column.empty() ? o.input_column : mobility ? "iq_a" : "i_a";
  const std::string out_name = !o.output_column.empty() ? o.output_column
                               : mobility               ? "theta_motor_rad"
                                                        : "u_v";
  const auto& ts = t.Column("t_s");
  const auto& x = t.Column(in_name);
  const auto& y = t.Column(out_name);
  if (t.rows() < 16) throw FileError(path, 0, 0, "too few samples for a periodic estimate");
  const double dt = (ts.back() - ts.front()) / static_cast<double>(t.rows() - 1);
  if (!(dt > 0.0)) throw t.ErrorAt(t.rows() - 1, t.Find("t_s"), "time must increase");
  double fs = 1.0 / dt;
  if (std::abs(fs - std::round(fs)) < 1e-6 * fs) fs = std::round(fs);
  std::size_t period = 0;
  if (o.period_s > 0.0) {
    period = static_cast<std::size_t>(std::llround(o.period_s * fs));
  } else {
    period = DetectPeriod(x, path);
  }
  const double spacing = fs / static_cast<double>(period);
  std::vector<std::size_t> lines;
  std::string lines_note;
  std::string lines_file = o.lines_file;
  if (lines_file.empty()) {
    const std::filesystem::path p(path);
    const std::string name = p.filename().string();
    const std::string stem = name.substr(0, name.find('.'));
    const std::filesystem::path beside = p.parent_path() / (stem + "-excited-lines-hz.txt");
    if (std::filesystem::exists(beside)) lines_file = beside.string();
  }
  if (!lines_file.empty()) {
    lines = LinesFromFile(lines_file, spacing);
    lines_note = "excited lines from " + lines_file;
  } else {
    const analysis::RealFft fft(period);
    const std::vector<std::complex<double>> spec = fft.Forward(x.data() + period);
    double peak = 0.0;
    for (std::size_t k = 1; k < spec.size(); ++k) peak = std::max(peak, std::abs(spec[k]));
    for (std::size_t k = 1; k + 1 < spec.size(); ++k)
      if (std::abs(spec[k]) >= 0.1 * peak) lines.push_back(k);
    lines_note = "excited lines detected in " + in_name;
  }
  analysis::ChannelPair pair;
  pair.sample_rate_hz = fs;
  pair.period_samples = period;
  pair.x = x;
  pair.y = y;
  pair.x_name = in_name;
  pair.y_name = out_name;
  pair.quantity = o.quantity;
  pair.output_jw_power = mobility ? 1 : 0;
  const analysis::FrfSummary est =
      analysis::EstimatePeriodicTransfer(pair, lines, analysis::PeriodicFrfOptions{});
  if (!est.usable) throw FileError(path, 0, 0, "periodic estimate failed: " + est.message);
  GapInput in;
  in.source = path;
  in.kind = "recording";
  in.frf = est.frf;
  in.sigma_dof = 2.0 * est.noise_dof;
  std::ostringstream os;
  os << "raw recording (" << in_name << " -> " << out_name << ", " << fs << " Hz, period " << period
     << " samples), " << lines_note << "; " << est.message;
  in.note = os.str();
  return in;
}

GapInput ReadRigidShaftJson(const nlohmann::json& j, const std::string& path,
                            const std::vector<double>& lines) {
  io::JsonObject o(j, "");
  o.RequiredString("model");
  analysis::NominalNetwork n;
  n.quantity = Quantity::kMobility;
  if (o.Has("gain_rad_per_s2_per_a")) {
    n.rigid.gain_rad_per_s2_per_a = o.RequiredNumber("gain_rad_per_s2_per_a");
    n.rigid.damping_per_s = o.Number("damping_per_s", 0.0);
  } else {
    const double kt = o.RequiredNumber("transmission_nm_per_a");
    const double inertia = o.RequiredNumber("inertia_kg_m2");
    const double b = o.Number("damping_nms_per_rad", 0.0);
    o.Require(inertia > 0.0, "inertia_kg_m2", "must be positive");
    n.rigid.gain_rad_per_s2_per_a = kt / inertia;
    n.rigid.damping_per_s = b / inertia;
    n.inertia_kg_m2 = inertia;
  }
  o.RejectUnknown();
  std::string why;
  if (!n.IsValid(&why)) throw io::ConfigError("rigid shaft " + path + ": " + why);
  GapInput in;
  in.source = path;
  in.kind = "rigid-shaft-json";
  in.model = n;
  in.inertia_kg_m2 = n.inertia_kg_m2;
  in.frf = analysis::EvaluateNetwork(n, {}, lines);
  in.note = "rigid shaft g / (s + a), given exactly";
  return in;
}

GapInput ReadMotorJson(const std::string& path, const std::vector<double>& lines) {
  const MotorSpec spec = LoadMotorJson(path);
  const analysis::ClampedMotor motor = spec.Motor();
  GapInput in;
  in.source = path;
  in.kind = "motor-json";
  in.frf = motor.Evaluate(lines);
  // J_r: the rotor's inertia (magnets, poles, hub), as the paper takes it and as
  // analysis::ClampedRotor uses it; a defect changes stiffness, not inertia.
  const analysis::RotorChainParams& rotor = spec.rotor;
  in.inertia_kg_m2 = rotor.magnets * (rotor.magnet_inertia_kg_m2 + rotor.pole_inertia_kg_m2) +
                     rotor.hub_inertia_kg_m2;
  in.tolerances = spec.tolerances;
  std::ostringstream os;
  os << "motor JSON " << spec.id << " (torsional chain, " << motor.chain.size()
     << " inertias) evaluated on the measured lines";
  os << "; rotor inertia " << in.inertia_kg_m2 << " kg m^2";
  in.note = os.str();
  return in;
}

}  // namespace

GapInput ReadGapSimulation(const std::string& path, const GapInputOptions& o,
                           const std::vector<double>& lines_hz) {
  if (!std::filesystem::exists(path)) throw FileError(path, 0, 0, "no such file");
  if (IsJson(path)) {
    if (lines_hz.empty()) throw FileError(path, 0, 0, "a model needs the measured lines");
    const nlohmann::json j = io::ReadJsonFile(path);
    const bool rigid = j.is_object() && j.value("model", "") == "rigid_shaft";
    GapInput in = rigid ? ReadRigidShaftJson(j, path, lines_hz) : ReadMotorJson(path, lines_hz);
    CheckQuantity(in.frf, o.quantity, path);
    return in;
  }
  GapInput in = ReadFrfFile(path, o.quantity);
  in.note += ", taken as noise-free";
  return in;
}

GapInput ReadGapMeasurement(const std::string& path, const GapInputOptions& o) {
  if (!std::filesystem::exists(path)) throw FileError(path, 0, 0, "no such file");
  GapInput in;
  if (!IsZma(path) && FirstLine(path).find("t_s") != std::string::npos &&
      FirstLine(path).find("f_hz") == std::string::npos) {
    in = ReadRecording(path, o);
  } else {
    in = ReadFrfFile(path, o.quantity);
  }
  if (!in.frf.has_sigma()) {
    if (in.frf.size() < 5) throw FileError(path, 0, 0, "too few lines to estimate the noise");
    in.frf.sigma = analysis::EstimateLineSigma(in.frf);
    in.sigma_estimated = true;
    in.sigma_dof = 0.0;
    in.note +=
        "; no sigma in the file: noise estimated from the line-to-line scatter "
        "(second differences, running median over 51 lines)";
  } else if (in.kind != "recording" && in.sigma_dof == 0.0) {
    // A file's sigma without its degrees of freedom: read them from sigma's own scatter
    // (analysis/gap/noise.h); a sigma without scatter stays exact.
    in.sigma_dof = analysis::EstimateSigmaDof(in.frf.sigma);
    std::ostringstream os;
    if (in.sigma_dof > 0.0)
      os << "; sigma^2 on " << std::lround(in.sigma_dof)
         << " degrees of freedom, estimated from sigma's line-to-line scatter (no sigma_dof "
            "column)";
    else
      os << "; sigma taken as exact (no sigma_dof column, no scatter in sigma)";
    in.note += os.str();
  }
  return in;
}

}  // namespace eol::io
