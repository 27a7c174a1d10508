#include "drivers/io/frf_files.h"

#include <cmath>
#include <fstream>
#include <locale>
#include <numbers>
#include <sstream>

#include "drivers/io/text_table.h"

namespace eol::io {
namespace {

std::ofstream OpenForWriting(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw FileError(path, 0, 0, "cannot open for writing");
  out.imbue(std::locale::classic());
  out.precision(17);
  return out;
}

void Finish(std::ofstream& out, const std::string& path) {
  out.flush();
  if (!out) throw FileError(path, 0, 0, "write failed");
}

// A ZMA line split on spaces, tabs and commas, with each field's 1-based column.
std::vector<std::pair<std::string_view, std::size_t>> SplitWords(std::string_view line) {
  std::vector<std::pair<std::string_view, std::size_t>> words;
  std::size_t i = 0;
  auto sep = [](char c) { return c == ' ' || c == '\t' || c == ','; };
  while (i < line.size()) {
    while (i < line.size() && sep(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !sep(line[i])) ++i;
    if (i > start) words.emplace_back(line.substr(start, i - start), start + 1);
  }
  return words;
}

}  // namespace

analysis::Frf ReadFrfCsv(const std::string& path, double* sigma_dof) {
  const CsvTable t = ReadCsvTable(path);
  analysis::Frf frf;
  frf.method = "file";
  const bool impedance =
      t.Find("re_ohm") != std::string::npos || t.Find("im_ohm") != std::string::npos;
  const char* re_name = impedance ? "re_ohm" : "re";
  const char* im_name = impedance ? "im_ohm" : "im";
  const char* sigma_name = impedance ? "sigma_ohm" : "sigma";
  frf.quantity = impedance ? analysis::Quantity::kImpedanceOhm : analysis::Quantity::kMobility;
  if (t.Find("f_hz") == std::string::npos || t.Find(re_name) == std::string::npos ||
      t.Find(im_name) == std::string::npos) {
    std::string have;
    for (const auto& n : t.names) have += (have.empty() ? "" : ",") + n;
    throw FileError(path, 1, 0,
                    "not an FRF CSV: need the columns f_hz,re_ohm,im_ohm[,sigma_ohm] or "
                    "f_hz,re,im[,sigma] (header: " +
                        have + ")");
  }
  const std::size_t cf = t.Find("f_hz"), cs = t.Find(sigma_name), cd = t.Find("sigma_dof");
  if (cd != std::string::npos && cs == std::string::npos)
    throw FileError(path, 1, 0,
                    std::string("a sigma_dof column needs the ") + sigma_name + " column");
  const auto& f = t.columns[cf];
  const auto& re = t.Column(re_name);
  const auto& im = t.Column(im_name);
  for (std::size_t r = 0; r < t.rows(); ++r) {
    if (!(f[r] > 0.0)) throw t.ErrorAt(r, cf, "frequency must be positive");
    if (r > 0 && !(f[r] > f[r - 1]))
      throw t.ErrorAt(r, cf,
                      "frequencies must increase strictly (previous line has " +
                          std::to_string(f[r - 1]) + ")");
    frf.freq_hz.push_back(f[r]);
    frf.value.emplace_back(re[r], im[r]);
    if (cs != std::string::npos) {
      const double s = t.columns[cs][r];
      if (!(s > 0.0)) throw t.ErrorAt(r, cs, "sigma must be positive");
      frf.sigma.push_back(s);
    }
    if (cd != std::string::npos) {
      const double d = t.columns[cd][r];
      if (d != 0.0 && !(d > 4.0)) throw t.ErrorAt(r, cd, "must be above 4 (or 0: sigma exact)");
      if (r > 0 && d != t.columns[cd][0]) {
        std::ostringstream first;
        first << t.columns[cd][0];
        throw t.ErrorAt(r, cd,
                        "must be the same on every line (the first line has " + first.str() + ")");
      }
    }
  }
  if (sigma_dof) *sigma_dof = cd != std::string::npos && t.rows() > 0 ? t.columns[cd][0] : 0.0;
  return frf;
}

void WriteFrfCsv(const std::string& path, const analysis::Frf& frf, double sigma_dof) {
  std::string why;
  if (!frf.Validate(&why)) throw FileError(path, 0, 0, "refusing to write an invalid FRF: " + why);
  if (!(sigma_dof == 0.0 || sigma_dof > 4.0))
    throw FileError(path, 0, 0,
                    "refusing to write a sigma_dof of " + std::to_string(sigma_dof) +
                        ": it must be above 4 (or 0: sigma exact)");
  const bool dof = frf.has_sigma() && sigma_dof > 0.0;
  std::ofstream out = OpenForWriting(path);
  const bool z = frf.quantity == analysis::Quantity::kImpedanceOhm;
  out << (z ? "f_hz,re_ohm,im_ohm" : "f_hz,re,im");
  if (frf.has_sigma()) out << (z ? ",sigma_ohm" : ",sigma");
  if (dof) out << ",sigma_dof";
  out << '\n';
  for (std::size_t k = 0; k < frf.size(); ++k) {
    out << frf.freq_hz[k] << ',' << frf.value[k].real() << ',' << frf.value[k].imag();
    if (frf.has_sigma()) out << ',' << frf.sigma[k];
    if (dof) out << ',' << sigma_dof;
    out << '\n';
  }
  Finish(out, path);
}

analysis::Frf ReadZma(const std::string& path) {
  LineReader in(path);
  analysis::Frf z;
  z.quantity = analysis::Quantity::kImpedanceOhm;
  z.method = "file";
  std::string line;
  const char* what[3] = {"frequency", "|Z|", "phase"};
  while (in.Next(&line)) {
    const auto words = SplitWords(line);
    if (words.empty() || words.front().first.front() == '*') continue;
    const std::size_t ln = in.line_number();
    if (words.size() < 3)
      throw FileError(path, ln, line.size() + 1,
                      "expected 3 fields (frequency, |Z|, phase in degrees), found " +
                          std::to_string(words.size()));
    double v[3];
    for (int c = 0; c < 3; ++c)
      v[c] = ParseNumber(words[static_cast<std::size_t>(c)].first, path, ln,
                         words[static_cast<std::size_t>(c)].second, what[c]);
    if (!(v[0] > 0.0)) throw FileError(path, ln, words[0].second, "frequency must be positive");
    if (!z.freq_hz.empty() && !(v[0] > z.freq_hz.back()))
      throw FileError(path, ln, words[0].second, "frequencies must increase strictly");
    if (v[1] < 0.0) throw FileError(path, ln, words[1].second, "|Z| must not be negative");
    z.freq_hz.push_back(v[0]);
    // Reduced to one turn first: a phase such as 1e308 degrees is finite but overflows in radians.
    z.value.push_back(std::polar(v[1], std::fmod(v[2], 360.0) * std::numbers::pi / 180.0));
  }
  if (z.size() == 0) throw FileError(path, 0, 0, "no data lines (an empty ZMA file)");
  return z;
}

void WriteZma(const std::string& path, const analysis::Frf& z) {
  std::string why;
  if (!z.Validate(&why)) throw FileError(path, 0, 0, "refusing to write an invalid FRF: " + why);
  std::ofstream out = OpenForWriting(path);
  out << "* frequency_hz |Z|_ohm phase_deg\n";
  for (std::size_t k = 0; k < z.size(); ++k)
    out << z.freq_hz[k] << ' ' << std::abs(z.value[k]) << ' '
        << std::arg(z.value[k]) * 180.0 / std::numbers::pi << '\n';
  Finish(out, path);
}

}  // namespace eol::io
