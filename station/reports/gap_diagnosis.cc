#include "station/reports/gap_diagnosis.h"

#include <stdlib.h>  // mkdtemp

#include <algorithm>
#include <cctype>
#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "analysis/gap/noise.h"
#include "drivers/io/file_error.h"
#include "drivers/io/json_config.h"

namespace eol::station {
namespace {

// A private folder for the uploads of one request, removed with everything in it.
class UploadFolder {
 public:
  UploadFolder() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "eol-gap-upload-XXXXXX").string();
    if (!mkdtemp(tmpl.data()))
      throw std::runtime_error("gap: cannot create a temporary folder for the uploads");
    path_ = tmpl;
  }
  ~UploadFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  UploadFolder(const UploadFolder&) = delete;
  UploadFolder& operator=(const UploadFolder&) = delete;

  // Writes the upload as file number `index`, keeping the extension of its name (the readers
  // pick the format by it); returns the path.
  std::string Write(std::size_t index, const GapUpload& upload) {
    std::string ext = std::filesystem::path(upload.name).extension().string();
    for (char& ch : ext)
      if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.') ch = '_';
    const std::string file = (path_ / ("input-" + std::to_string(index) + ext)).string();
    std::ofstream out(file, std::ios::binary);
    out << upload.text;
    out.close();
    if (!out) throw std::runtime_error("gap: cannot stage the upload '" + upload.name + "'");
    names_.emplace_back(file, upload.name);
    return file;
  }

  // The message with every staged path replaced by its upload's name.
  std::string Rename(std::string message) const {
    for (const auto& [file, name] : names_)
      for (std::size_t at; (at = message.find(file)) != std::string::npos;)
        message.replace(at, file.size(), name);
    return message;
  }

 private:
  std::filesystem::path path_;
  std::vector<std::pair<std::string, std::string>> names_;
};

}  // namespace

void KeepBand(analysis::Frf* f, double lo, double hi) {
  analysis::Frf out;
  out.quantity = f->quantity;
  out.method = f->method;
  for (std::size_t k = 0; k < f->size(); ++k) {
    if ((lo > 0.0 && f->freq_hz[k] < lo) || (hi > 0.0 && f->freq_hz[k] > hi)) continue;
    out.freq_hz.push_back(f->freq_hz[k]);
    out.value.push_back(f->value[k]);
    if (f->has_sigma()) out.sigma.push_back(f->sigma[k]);
  }
  *f = std::move(out);
}

analysis::CalibrationSummary CalibrateToSimulation(const io::GapInput& sim, double inertia) {
  if (sim.model) {
    analysis::CalibrationSummary c;
    c.usable = true;
    c.nominal = *sim.model;
    if (c.nominal.inertia_kg_m2 <= 0.0) c.nominal.inertia_kg_m2 = inertia;
    c.message = "nominal given exactly by the model";
    c.params = {{"gain_rad_per_s2_per_a", "rad/s^2/A", c.nominal.rigid.gain_rad_per_s2_per_a, 0.0},
                {"damping_per_s", "1/s", c.nominal.rigid.damping_per_s, 0.0}};
    return c;
  }
  analysis::CalibrationOptions o;
  o.inertia_kg_m2 = inertia;
  return analysis::CalibrateNominal(sim.frf, o);
}

namespace {

// Degrees of freedom of a measured unit's sigma^2 (GapRunOptions::sigma_dof).
double UnitSigmaDof(const io::GapInput& m, const GapRunOptions& o) {
  if (m.sigma_estimated || o.sigma_exact) return 0.0;
  return o.sigma_dof > 0.0 ? o.sigma_dof : m.sigma_dof * (2 * o.sigma_pool + 1);
}

}  // namespace

void ReadGapInputs(const std::string& simulation, const std::vector<std::string>& measured,
                   const GapRunOptions& o, GapReport* r) {
  r->quantity = o.io.quantity;
  r->sigma_pool = o.sigma_pool;
  r->sigma_dof = o.sigma_exact ? 0.0 : o.sigma_dof;
  r->measured.clear();
  for (const std::string& path : measured) {
    io::GapInput m = io::ReadGapMeasurement(path, o.io);
    // The file's own degrees of freedom (column, periodic estimate or scatter, in the note)
    // give way to the options'; the note says which one the fit uses.
    if (!m.sigma_estimated && o.sigma_exact)
      m.note += "; sigma taken as exact (--sigma-exact)";
    else if (!m.sigma_estimated && o.sigma_dof > 0.0)
      m.note += "; sigma^2 on " + std::to_string(std::lround(o.sigma_dof)) +
                " degrees of freedom as the options give (used instead)";
    KeepBand(&m.frf, o.f_lo_hz, o.f_hi_hz);
    if (m.frf.size() < 10) throw io::FileError(path, 0, 0, "fewer than 10 lines in the band");
    // The report's: the option's, else the smallest of the files' (each unit's is in its note).
    const double dof = UnitSigmaDof(m, o);
    if (dof > 0.0 && (r->sigma_dof == 0.0 || dof < r->sigma_dof)) r->sigma_dof = dof;
    r->measured.push_back(std::move(m));
  }
  if (r->measured.empty()) throw std::invalid_argument("gap: no measured unit");
  r->simulation = io::ReadGapSimulation(simulation, o.io, r->measured.front().frf.freq_hz);
  KeepBand(&r->simulation.frf, o.f_lo_hz, o.f_hi_hz);
}

void DiagnoseGapReport(const GapRunOptions& o, GapReport* r) {
  const bool impedance = o.io.quantity == analysis::Quantity::kImpedanceOhm;
  if (o.inertia_kg_m2 > 0.0) {
    r->inertia_kg_m2 = o.inertia_kg_m2;
    r->inertia_source = "given";
  } else if (r->simulation.inertia_kg_m2 > 0.0) {
    r->inertia_kg_m2 = r->simulation.inertia_kg_m2;
    r->inertia_source = "simulation";
  } else if (impedance && o.fallback_inertia_kg_m2 > 0.0) {
    r->inertia_kg_m2 = o.fallback_inertia_kg_m2;
    r->inertia_source = "recipe";
  } else {
    r->inertia_kg_m2 = 0.0;
    r->inertia_source = "";
  }
  r->calibration = CalibrateToSimulation(r->simulation, r->inertia_kg_m2);
  if (!r->calibration.usable)
    throw GapNotUsable(r->simulation.source + ": " + r->calibration.message);
  std::vector<analysis::GapUnit> units;
  for (const io::GapInput& m : r->measured) {
    analysis::GapUnit u;
    u.name = m.source;
    u.freq_hz = m.frf.freq_hz;
    u.value = m.frf.value;
    u.sigma = m.sigma_estimated ? m.frf.sigma : analysis::PoolLineSigma(m.frf, o.sigma_pool);
    u.sigma_smooth = m.sigma_estimated || o.sigma_pool > 0;
    u.sigma_dof = UnitSigmaDof(m, o);
    units.push_back(std::move(u));
  }
  analysis::GapOptions go;
  go.try_pairs = o.try_pairs;
  go.effects = o.effects;
  go.calibrate = o.calibrate;
  r->tolerance_source = "default";
  if (r->simulation.tolerances) {
    go.tolerances = *r->simulation.tolerances;
    r->tolerance_source = "simulation";
  }
  if (!o.tolerances.empty()) {
    std::string why;
    if (!analysis::ParseTolerances(o.tolerances, &go.tolerances, &why))
      throw std::invalid_argument("--tolerances: " + why);
    r->tolerance_source = "given";
  }
  r->tolerances = go.tolerances;
  r->gap = analysis::DiagnoseGap(r->calibration.nominal, units, go);
  if (!r->gap.usable) throw GapNotUsable(r->gap.message);
  // A residual a little above the files' sigma with nothing to explain it: the usual cause is
  // a sigma estimated from few periods and taken as exact (8 periods: E|r|^2 = 14 / 12).
  const bool exact_from_files = std::all_of(
      r->measured.begin(), r->measured.end(),
      [&](const io::GapInput& m) { return !m.sigma_estimated && UnitSigmaDof(m, o) == 0.0; });
  if (r->gap.effect == "unexplained" && exact_from_files && r->gap.sigma_scale < 1.5)
    r->gap.message +=
        "; the measured files' sigma was taken as exact: if it was estimated from a few "
        "periods, give its degrees of freedom (--sigma-periods P, --sigma-dof N or a "
        "sigma_dof column; a sigma with too little scatter to read them from reads as exact)";
  analysis::CalibrationOptions co;
  r->features.clear();
  for (const analysis::GapUnit& u : units)
    r->features.push_back(analysis::CompareFeatures(r->calibration, u, o.io.quantity, co));
}

GapReport DiagnoseGapUploads(const GapUpload& simulation, const std::vector<GapUpload>& measured,
                             const GapRunOptions& options) {
  UploadFolder folder;
  GapReport r;
  try {
    const std::string sim_path = folder.Write(0, simulation);
    std::vector<std::string> paths;
    for (std::size_t i = 0; i < measured.size(); ++i)
      paths.push_back(folder.Write(i + 1, measured[i]));
    ReadGapInputs(sim_path, paths, options, &r);
  } catch (const io::FileError& e) {
    throw io::FileError(folder.Rename(e.file()), e.line(), e.column(), folder.Rename(e.message()));
  } catch (const io::ConfigError& e) {
    throw io::ConfigError(folder.Rename(e.what()));
  } catch (const std::exception& e) {  // whatever else a reader refuses, named by the upload
    throw std::invalid_argument(folder.Rename(e.what()));
  }
  r.simulation.source = simulation.name;
  for (std::size_t i = 0; i < measured.size(); ++i) r.measured[i].source = measured[i].name;
  DiagnoseGapReport(options, &r);
  return r;
}

io::Chart GapChart(const GapReport& r) {
  const io::GapInput& meas = r.measured.front();
  const bool mobility = r.quantity == analysis::Quantity::kMobility;
  const analysis::NominalNetwork& n = r.calibration.nominal;
  const auto& f = meas.frf.freq_hz;
  io::Chart fig;
  fig.panel_height_px = 260;
  fig.title = "eol gap: " + r.gap.effect + "  (g " + std::to_string(r.gap.gap_before).substr(0, 6) +
              " -> " + std::to_string(r.gap.gap_after).substr(0, 6) + ")  " + meas.source;
  const bool log_x = f.back() / f.front() > 10.0;
  std::vector<io::ChartBand> shaded;
  for (const auto& b : r.gap.where) {
    io::ChartBand band;
    band.label = shaded.empty() ? "where the gap is" : "";
    band.lo = b.band.f_lo_hz;
    band.hi = b.band.f_hi_hz;
    band.colour = {0.957, 0.635, 0.380};
    band.alpha = 0.25;
    shaded.push_back(band);
  }
  auto series = [&](const std::string& label, io::Colour colour, const std::vector<double>& y,
                    bool markers, double width, bool dashed) {
    io::ChartSeries c;
    c.label = label;
    c.colour = colour;
    c.x = f;
    c.y = y;
    c.line = !markers;
    c.markers = markers;
    c.marker_radius = 1.6;
    c.width = width;
    c.style = dashed ? io::LineStyle::kDashed : io::LineStyle::kSolid;
    return c;
  };
  auto base = [&](const std::string& y_label, bool log_y) {
    io::ChartPanel p;
    p.x_label = "frequency (Hz)";
    p.y_label = y_label;
    p.log_x = log_x;
    p.log_y = log_y;
    p.vbands = shaded;
    return p;
  };
  // Curves: measured, simulated (the calibrated nominal), corrected (nominal + winner).
  std::vector<double> m1, m2, s1, s2, c1, c2, before, after;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const std::complex<double> hm = meas.frf.value[k];
    const std::complex<double> hs = n.At(f[k]);
    const std::complex<double> hc =
        analysis::EvaluateNetwork(r.gap.nominal_after, r.gap.winner, f[k]);
    if (mobility) {
      m1.push_back(std::abs(hm));
      s1.push_back(std::abs(hs));
      c1.push_back(std::abs(hc));
      m2.push_back(std::arg(hm) * 180.0 / std::numbers::pi);
      s2.push_back(std::arg(hs) * 180.0 / std::numbers::pi);
      c2.push_back(std::arg(hc) * 180.0 / std::numbers::pi);
    } else {
      // Im Z minus the nominal's w L shows the motional part under the inductive background.
      const double wl = 2.0 * std::numbers::pi * f[k] * n.motional.l_h;
      m1.push_back(hm.real());
      s1.push_back(hs.real());
      c1.push_back(hc.real());
      m2.push_back(hm.imag() - wl);
      s2.push_back(hs.imag() - wl);
      c2.push_back(hc.imag() - wl);
    }
    before.push_back(std::abs(hm - hs) / meas.frf.sigma[k]);
    after.push_back(std::abs(hm - hc) / meas.frf.sigma[k]);
  }
  auto panel = [&](const std::string& label, const std::vector<double>& m,
                   const std::vector<double>& s, const std::vector<double>& c, bool log_y) {
    io::ChartPanel p = base(label, log_y);
    p.series.push_back(series("measured", {0.267, 0.267, 0.267}, m, true, 1.0, false));
    p.series.push_back(series("simulated", io::kChartBlue, s, false, 1.6, true));
    p.series.push_back(series("corrected", io::kChartRed, c, false, 1.6, false));
    return p;
  };
  if (mobility) {
    fig.panels.push_back(panel("|H| (rad/s/A)", m1, s1, c1, true));
    fig.panels.push_back(panel("phase H (deg)", m2, s2, c2, false));
  } else {
    fig.panels.push_back(panel("Re Z (ohm)", m1, s1, c1, false));
    fig.panels.push_back(panel("Im Z - w L_nominal (ohm)", m2, s2, c2, false));
  }
  io::ChartPanel res = base("|residual| / sigma", true);
  io::ChartLine one;
  one.label = "1 sigma";
  one.value = 1.0;
  one.colour = io::kChartGrey;
  one.style = io::LineStyle::kDotted;
  res.hlines.push_back(one);
  res.series.push_back(series("simulated", io::kChartBlue, before, false, 1.0, false));
  res.series.push_back(series("corrected", io::kChartRed, after, false, 1.0, false));
  fig.panels.push_back(res);
  return fig;
}

}  // namespace eol::station
