#include "station/bench/fit_bench_peer.h"

#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace eol::station {
namespace {

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Removes the directory and its contents on destruction.
struct ScratchDir {
  std::filesystem::path path;
  ScratchDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "eol-fit-bench-XXXXXX").string();
    if (mkdtemp(tmpl.data())) path = tmpl;
  }
  ~ScratchDir() {
    std::error_code ec;
    if (!path.empty()) std::filesystem::remove_all(path, ec);
  }
};

}  // namespace

ScipyPeerResult RunScipyPipelinePeer(const analysis::FitBenchResult& result,
                                     const analysis::FitBenchOptions& o, const std::string& python,
                                     const std::string& script) {
  ScipyPeerResult peer;
  if (access(python.c_str(), X_OK) != 0) {
    peer.message = python + " not found";
    return peer;
  }
  if (!std::filesystem::exists(script)) {
    peer.message = script + " not found";
    return peer;
  }
  if (result.kept.empty()) {
    peer.message = "no recordings kept for the peer";
    return peer;
  }
  ScratchDir dir;
  if (dir.path.empty()) {
    peer.message = "cannot create a temporary directory";
    return peer;
  }
  nlohmann::json manifest = {
      {"sample_rate_hz", result.excitation.sample_rate_hz},
      {"period_samples", result.excitation.period_samples},
      {"lines", result.excitation.lines},
      {"transient_periods", o.transient_periods},
      {"noise_smoothing_lines", o.analysis.frf.noise_smoothing_lines},
      {"f0_min_hz", o.analysis.fit.f0_min_hz > 0 ? o.analysis.fit.f0_min_hz : o.excitation.f_lo_hz},
      {"f0_max_hz", o.analysis.fit.f0_max_hz > 0 ? o.analysis.fit.f0_max_hz : o.excitation.f_hi_hz},
      {"q_min", o.analysis.fit.q_min},
      {"q_max", o.analysis.fit.q_max},
      {"grid_f0", o.analysis.fit.grid_f0},
      {"grid_q", o.analysis.fit.grid_q},
      {"recordings", nlohmann::json::array()}};
  for (std::size_t r = 0; r < result.kept.size(); ++r) {
    const auto path = dir.path / ("rec" + std::to_string(r) + ".f64");
    std::ofstream out(path, std::ios::binary);
    for (const std::vector<double>* ch : {&result.kept[r].voltage_v, &result.kept[r].current_a})
      out.write(reinterpret_cast<const char*>(ch->data()),
                static_cast<std::streamsize>(ch->size() * sizeof(double)));
    if (!out) {
      peer.message = "cannot write " + path.string();
      return peer;
    }
    manifest["recordings"].push_back(path.string());
  }
  const auto manifest_path = dir.path / "manifest.json";
  std::ofstream(manifest_path) << manifest.dump();

  const std::string cmd = Quote(python) + " " + Quote(script) + " " + Quote(manifest_path.string());
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) {
    peer.message = "cannot run " + cmd;
    return peer;
  }
  std::string text;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) text.append(buf, n);
  const int status = pclose(pipe);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (code != 0 || j.is_discarded() || !j.contains("runs")) {
    peer.message = "the SciPy pipeline failed (exit " + std::to_string(code) + ")" +
                   (code == 2 ? ": python3-scipy is missing" : "") + ": " + text;
    return peer;
  }
  peer.ran = true;
  peer.scipy_version = j.value("scipy_version", "?");
  peer.ms_mean = j.value("ms_mean", 0.0);
  peer.ms_min = j.value("ms_min", 0.0);
  for (const auto& r : j["runs"]) peer.f0_hz.push_back(r.value("f0_hz", 0.0));
  peer.message = "ran " + std::to_string(peer.f0_hz.size()) + " recordings";
  return peer;
}

}  // namespace eol::station
