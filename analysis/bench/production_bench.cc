#include "analysis/bench/production_bench.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <random>
#include <thread>

#include "analysis/impedance_analysis.h"
#include "analysis/qc/line_measurement.h"

namespace eol::analysis {
namespace {

constexpr std::uint64_t kGoldenIndexBase = 1000000000ULL;
constexpr std::uint64_t kPodIndexBase = 2000000000ULL;           // + sweep x 1e8 + unit
constexpr std::uint64_t kExtensionSeed = 0xA5A5A5A55A5A5A5AULL;  // a sequential look's noise

std::size_t ClassIndex(DefectClass c) {
  for (std::size_t i = 0; i < kAllDefectClasses.size(); ++i)
    if (kAllDefectClasses[i] == c) return i;
  return 0;
}

std::uint64_t NoiseSeed(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t z = (seed + 0x9E3779B97F4A7C15ULL) ^ (index * 0xD6E8FEB86659FD93ULL);
  z = (z ^ (z >> 32)) * 0xD6E8FEB86659FD93ULL;
  return z ^ (z >> 32);
}

struct Measured {
  Frf frf;
  ImpedanceAnalysis analysis;
};

Measured MeasureUnit(const ProductionBenchOptions& o, const LineMeasurementSetup& setup,
                     const LineUnit& unit, std::uint64_t index) {
  Measured m;
  m.frf =
      MeasureLineUnit(setup, ModalImpedance(unit.motor, setup.freq_hz), NoiseSeed(o.seed, index));
  m.analysis = AnalyzeImpedance(m.frf, o.fit);
  return m;
}

Verdict VerdictWith(const std::vector<MeasurementSpec>& limits, const std::vector<CurveMask>& masks,
                    const std::optional<BondIndexDefinition>& bond_index, const Measured& m) {
  std::vector<MeasurementSpec> specs = limits;
  std::map<std::string, Estimate> values = m.analysis.values;
  if (bond_index) AddBondIndex(values, *bond_index);
  for (const CurveMask& mask : masks) {
    specs.push_back(mask.Spec());
    if (m.analysis.usable)
      values[mask.MeasurementName()] =
          Estimate{static_cast<double>(CheckMask(m.frf, mask).lines_outside), 0.0};
  }
  return Judge(specs, values);
}

Outcome JudgeWith(const std::vector<MeasurementSpec>& limits, const std::vector<CurveMask>& masks,
                  const std::optional<BondIndexDefinition>& bond_index, const Measured& m) {
  return VerdictWith(limits, masks, bond_index, m).outcome;
}

// The station's sequential decision (station/daemon/recipe.h SequentialPolicy) under the limits in
// force (the taught ones): while a measurement is undecided, a further look of
// o.extend_periods periods with its own noise, combined by inverse variance and analysed
// again. Returns the looks taken.
int ExtendWhileUndecided(const ProductionBenchOptions& o, const LineMeasurementSetup& extension,
                         const TeachSummary& teach, const LineUnit& unit, std::uint64_t index,
                         Measured& m) {
  int looks = 1;
  for (int e = 0; e < o.max_extensions && m.analysis.usable; ++e) {
    const Verdict v = VerdictWith(teach.limits, teach.masks, teach.bond_index, m);
    if (UndecidedMeasurements(v.measurements, o.confidence_z).empty()) break;
    const Frf more = MeasureLineUnit(extension, ModalImpedance(unit.motor, extension.freq_hz),
                                     NoiseSeed(o.seed ^ kExtensionSeed * (e + 1), index));
    m.frf = CombineIndependent(m.frf, more);
    m.analysis = AnalyzeImpedance(m.frf, o.fit);
    ++looks;
  }
  return looks;
}

double ResonanceHz(const Measured& m) {
  const auto it = m.analysis.values.find("resonance_f_hz");
  return m.analysis.usable && it != m.analysis.values.end() ? it->second.value : std::nan("");
}

// Runs body(i) for i in [0, n) on `threads` threads, reporting each finished i to
// o.progress under `phase`.
template <typename Body>
void ParallelFor(const ProductionBenchOptions& o, std::string_view phase, int n, int threads,
                 Body body) {
  std::atomic<int> next{0};
  std::atomic<std::int64_t> done{0};
  if (o.progress) o.progress(phase, 0, n);
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&] {
      for (int i = next++; i < n; i = next++) {
        body(i);
        const std::int64_t d = ++done;
        if (o.progress) o.progress(phase, d, n);
      }
    });
  for (auto& t : pool) t.join();
}

void RunPodSweep(const ProductionBenchOptions& o, const LineMeasurementSetup& setup,
                 const LineMeasurementSetup& extension, const TeachSummary& teach,
                 std::uint64_t sweep, PodSweep& w) {
  const auto n = static_cast<std::size_t>(o.pod_units);
  w.data.assign(n, HitMiss{});
  w.f0_hz.assign(n, std::nan(""));
  ParallelFor(o, "POD " + w.name, o.pod_units, o.threads, [&](int i) {
    const std::uint64_t index =
        kPodIndexBase + sweep * 100000000ULL + static_cast<std::uint64_t>(i);
    std::mt19937_64 gen(NoiseSeed(o.seed, index) ^ 0x5DEECE66DULL);
    const double loss = std::uniform_real_distribution<double>(o.pod_loss_lo, o.pod_loss_hi)(gen);
    RotorChainParams nominal = o.rotor;
    nominal.bond_poor = {o.rotor.bond.stiffness_nm_per_rad * (1.0 - loss),
                         o.rotor.bond.damping_nms_per_rad * (1.0 - loss)};
    const LineUnit unit = DrawLineUnit(nominal, o.spread, w.defect, o.seed, index);
    Measured m = MeasureUnit(o, setup, unit, index);
    if (o.max_extensions > 0) ExtendWhileUndecided(o, extension, teach, unit, index, m);
    const auto k = static_cast<std::size_t>(i);
    w.data[k] = {loss, JudgeWith(teach.limits, teach.masks, teach.bond_index, m) != Outcome::kPass};
    w.f0_hz[k] = ResonanceHz(m);
  });
  w.fit = FitPod(w.data, o.pod);
}

void Count(ClassCounts& c, Outcome o) {
  ++c.units;
  if (o == Outcome::kPass)
    ++c.pass;
  else if (o == Outcome::kFail)
    ++c.fail;
  else
    ++c.error;
}

}  // namespace

const char* ToString(BenchRule r) {
  switch (r) {
    case BenchRule::kTaught:
      return "taught";
    case BenchRule::kRecipe:
      return "recipe";
    case BenchRule::kNaive:
      return "naive";
  }
  return "taught";
}

bool ProductionBenchOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (units < 1 || units > 10000000) return fail("units must be in [1, 10000000]");
  if (golden_units < 3 || golden_units > 100000) return fail("golden_units must be in [3, 100000]");
  if (threads < 1 || threads > 64) return fail("threads must be in [1, 64]");
  if (periods < 1) return fail("periods must be at least 1");
  if (max_extensions < 0 || max_extensions > 5) return fail("max_extensions must be in [0, 5]");
  if (max_extensions > 0 && (extend_periods < 1 || !(confidence_z > 0.0)))
    return fail("a sequential bench needs extend_periods >= 1 and confidence_z > 0");
  if (!(voltage_noise_v > 0.0 && current_noise_a > 0.0))
    return fail("the channel noise must be positive (the sigma of every line comes from it)");
  std::string w;
  if (!excitation.IsValid(&w)) return fail("excitation: " + w);
  if (!fit.IsValid(&w)) return fail("fit: " + w);
  if (!teach.IsValid(&w)) return fail("teach: " + w);
  if (!rotor.IsValid(&w)) return fail("rotor: " + w);
  if (!rotor.fixture) return fail("rotor: the line clamps in a fixture (fixture must be set)");
  if (!spread.IsValid(&w)) return fail("spread: " + w);
  if (!rates.IsValid(&w)) return fail("rates: " + w);
  if (!naive.IsValid(&w)) return fail(w);
  if (declared.empty()) return fail("the recipe declares no scalar limit");
  if (pod_units < 0 || pod_units > 1000000) return fail("pod_units must be in [0, 1000000]");
  if (!(pod_loss_lo > 0.0 && pod_loss_lo <= pod_loss_hi && pod_loss_hi < 1.0))
    return fail("pod losses must satisfy 0 < lo <= hi < 1");
  if (!pod.IsValid(&w)) return fail("pod: " + w);
  return true;
}

const ClassCounts& ProductionBenchSummary::Counts(BenchRule rule, DefectClass c) const {
  return counts[static_cast<std::size_t>(rule)][ClassIndex(c)];
}

double ProductionBenchSummary::EscapeRate(BenchRule rule, DefectClass c) const {
  const ClassCounts& k = Counts(rule, c);
  return k.units ? static_cast<double>(k.pass) / k.units : 0.0;
}

double ProductionBenchSummary::FalseRejectRate(BenchRule rule) const {
  const ClassCounts& k = Counts(rule, DefectClass::kGood);
  return k.units ? static_cast<double>(k.fail + k.error) / k.units : 0.0;
}

ProductionBenchSummary RunProductionBench(const ProductionBenchOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  ProductionBenchSummary s;
  std::string why;
  if (!o.IsValid(&why)) {
    s.message = "production bench options: " + why;
    return s;
  }
  const LineMeasurementSetup setup =
      MakeLineMeasurement(o.excitation, o.periods, o.voltage_noise_v, o.current_noise_a);
  const int threads = o.threads;
  const LineMeasurementSetup extension =
      o.max_extensions > 0 ? MakeLineMeasurement(o.excitation, o.extend_periods, o.voltage_noise_v,
                                                 o.current_noise_a)
                           : setup;

  // 1. Golden units and teaching.
  std::vector<GoldenUnit> golden(static_cast<std::size_t>(o.golden_units));
  std::vector<int> golden_ok(golden.size(), 0);
  ParallelFor(o, "golden units", o.golden_units, threads, [&](int k) {
    const auto i = static_cast<std::size_t>(k);
    const std::uint64_t index = kGoldenIndexBase + i;
    const LineUnit unit = DrawLineUnit(o.rotor, o.spread, DefectClass::kGood, o.seed, index);
    Measured m = MeasureUnit(o, setup, unit, index);
    golden[i].label = "golden-" + std::to_string(i);
    if (!m.analysis.usable) return;
    for (const auto& [name, e] : m.analysis.values) golden[i].values[name] = e.value;
    golden[i].curve = std::move(m.frf);
    golden_ok[i] = 1;
  });
  std::vector<GoldenUnit> usable_golden;
  for (std::size_t i = 0; i < golden.size(); ++i)
    if (golden_ok[i]) usable_golden.push_back(std::move(golden[i]));
  s.teach = TeachLimits(o.declared, usable_golden, o.teach);
  s.golden_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!s.teach.usable) {
    s.message = "teaching failed: " + s.teach.message;
    return s;
  }

  // 2. Production units, judged three ways.
  std::mutex merge;
  std::atomic<int> next{0};
  std::atomic<std::int64_t> done{0};
  if (o.progress) o.progress("production units", 0, o.units);
  auto work = [&] {
    ProductionBenchSummary local;
    for (int i = next++; i < o.units; i = next++) {
      const auto index = static_cast<std::uint64_t>(i);
      const LineUnit unit = DrawLineUnit(o.rotor, o.spread, o.rates, o.seed, index);
      Measured m = MeasureUnit(o, setup, unit, index);
      const std::size_t c = ClassIndex(unit.defect);
      if (o.max_extensions > 0 && ExtendWhileUndecided(o, extension, s.teach, unit, index, m) > 1)
        ++local.extended[c];
      Count(local.counts[0][c], JudgeWith(s.teach.limits, s.teach.masks, s.teach.bond_index, m));
      Count(local.counts[1][c], JudgeWith(o.declared, o.recipe_masks, o.recipe_bond_index, m));
      Count(local.counts[2][c], NaivePass(m.frf, o.naive) ? Outcome::kPass : Outcome::kFail);
      const double f0 = ResonanceHz(m);
      if (std::isfinite(f0)) local.f0_hz[c].push_back(f0);
      const std::int64_t d = ++done;
      if (o.progress) o.progress("production units", d, o.units);
    }
    const std::lock_guard<std::mutex> lock(merge);
    for (std::size_t r = 0; r < kBenchRules.size(); ++r)
      for (std::size_t c = 0; c < kAllDefectClasses.size(); ++c) {
        s.counts[r][c].units += local.counts[r][c].units;
        s.counts[r][c].pass += local.counts[r][c].pass;
        s.counts[r][c].fail += local.counts[r][c].fail;
        s.counts[r][c].error += local.counts[r][c].error;
      }
    for (std::size_t c = 0; c < kAllDefectClasses.size(); ++c) s.extended[c] += local.extended[c];
    for (std::size_t c = 0; c < kAllDefectClasses.size(); ++c)
      s.f0_hz[c].insert(s.f0_hz[c].end(), local.f0_hz[c].begin(), local.f0_hz[c].end());
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(work);
  for (auto& t : pool) t.join();

  // 3. POD sweeps.
  if (o.pod_units > 0) {
    s.pod.resize(2);
    s.pod[0].name = "one_magnet";
    s.pod[0].defect = DefectClass::kOneSoftMagnet;
    s.pod[1].name = "all_magnets";
    s.pod[1].defect = DefectClass::kAllSoft;
    for (std::size_t k = 0; k < s.pod.size(); ++k)
      RunPodSweep(o, setup, extension, s.teach, k, s.pod[k]);
  }

  s.units = o.units;
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.usable = true;
  s.message = std::to_string(o.units) + " units judged after teaching from " +
              std::to_string(s.teach.units_used) + " golden units";
  return s;
}

}  // namespace eol::analysis
