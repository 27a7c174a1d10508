#include "station/reports/spc_charts.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"

namespace eol::station {
namespace {

// Charts print 4 significant digits ("UCL 417.8"); "none" for a number that does not exist.
std::string Num(double v, int digits = 4) {
  return std::isfinite(v) ? analysis::Significant(v, digits) : "none";
}

std::string WithUnit(double v, const std::string& unit) {
  return Num(v) + (unit.empty() || unit == "1" ? "" : " " + unit);
}

std::string Axis(const SpcSeries& s) {
  return s.measurement + (s.unit.empty() || s.unit == "1" ? "" : " (" + s.unit + ")");
}

io::ChartLine Line(const std::string& label, double v, io::Colour c, io::LineStyle style) {
  io::ChartLine l;
  l.label = label;
  l.value = v;
  l.colour = c;
  l.style = style;
  return l;
}

// The recipe's limits as a shaded band and labelled lines (LSL, USL) on the value axis.
void AddSpecLimits(const SpcSeries& s, io::ChartPanel& p, bool vertical) {
  if (!s.limit.lo && !s.limit.hi) return;
  io::ChartBand band;
  band.lo = s.limit.lo ? *s.limit.lo : -INFINITY;
  band.hi = s.limit.hi ? *s.limit.hi : INFINITY;
  band.alpha = 0.10;
  band.label = "recipe limits [" + (s.limit.lo ? Num(*s.limit.lo) : std::string("-")) + ", " +
               (s.limit.hi ? Num(*s.limit.hi) : std::string("-")) + "]" +
               (s.unit.empty() || s.unit == "1" ? "" : " " + s.unit);
  auto& lines = vertical ? p.vlines : p.hlines;
  (vertical ? p.vbands : p.hbands).push_back(band);
  if (s.limit.lo)
    lines.push_back(Line("LSL " + WithUnit(*s.limit.lo, s.unit), *s.limit.lo, io::kChartBlack,
                         io::LineStyle::kSolid));
  if (s.limit.hi)
    lines.push_back(Line("USL " + WithUnit(*s.limit.hi, s.unit), *s.limit.hi, io::kChartBlack,
                         io::LineStyle::kSolid));
}

void AddControlLines(const analysis::ControlLimits& l, io::ChartPanel& p, bool lcl) {
  p.hlines.push_back(
      Line("centre " + Num(l.centre), l.centre, io::kChartGreen, io::LineStyle::kSolid));
  p.hlines.push_back(Line("UCL " + Num(l.ucl), l.ucl, io::kChartRed, io::LineStyle::kDashed));
  if (lcl)
    p.hlines.push_back(Line("LCL " + Num(l.lcl), l.lcl, io::kChartRed, io::LineStyle::kDashed));
}

io::ChartSeries Points(const std::string& label, std::vector<double> x, std::vector<double> y) {
  io::ChartSeries s;
  s.label = label;
  s.x = std::move(x);
  s.y = std::move(y);
  s.markers = true;
  s.width = 1.0;
  return s;
}

// The FAIL units among `points` (one per unit) as orange markers, labelled with their count.
void AddFailMarks(const SpcSeries& s, const std::vector<double>& x, io::ChartPanel& p) {
  io::ChartSeries f;
  f.colour = io::kChartOrange;
  f.line = false;
  f.markers = true;
  f.marker_radius = 3.5;
  for (std::size_t i = 0; i < s.values.size() && i < s.failed.size(); ++i)
    if (s.failed[i]) {
      f.x.push_back(x[i]);
      f.y.push_back(s.values[i]);
    }
  if (f.x.empty()) return;
  f.label = "FAIL unit (" + std::to_string(f.x.size()) + ")";
  p.series.push_back(f);
}

// Alarm points as red rings and their texts as notes (at most 6 listed).
void AddAlarms(const std::vector<NamedAlarm>& alarms, const std::vector<double>& x,
               const std::vector<double>& y, io::ChartPanel& p) {
  if (alarms.empty()) {
    p.notes.push_back("no run-rule alarm (rules 1, 2, 3)");
    return;
  }
  io::ChartSeries s;
  s.label = "run-rule alarm (" + std::to_string(alarms.size()) + ")";
  s.colour = io::kChartRed;
  s.line = false;
  s.markers = true;
  s.marker_radius = 5.0;
  for (const NamedAlarm& a : alarms) {
    s.x.push_back(x[a.alarm.index]);
    s.y.push_back(y[a.alarm.index]);
  }
  p.series.push_back(s);
  for (std::size_t i = 0; i < alarms.size() && i < 6; ++i) p.notes.push_back(alarms[i].text);
  if (alarms.size() > 6)
    p.notes.push_back("... and " + std::to_string(alarms.size() - 6) + " more");
}

std::vector<double> Iota(std::size_t n, double first = 1.0) {
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = first + static_cast<double>(i);
  return x;
}

std::string KindName(ChartKind k, std::size_t subgroup) {
  switch (k) {
    case ChartKind::kIMr:
      return "individuals / moving range (I-MR)";
    case ChartKind::kXbarR:
      return "X-bar / R, subgroups of " + std::to_string(subgroup);
    case ChartKind::kHistogram:
      return "histogram";
  }
  return "";
}

// The baseline's statement and caveat as notes of the chart's first panel.
void AddBaselineNotes(const Baseline& b, const analysis::PhasedChart& c, io::ChartPanel& p) {
  p.notes.push_back(b.text);
  if (!c.caveat.empty()) p.notes.push_back(c.caveat);
}

std::vector<io::ChartPanel> ImrPanels(const SpcSeries& s, const analysis::SpcRuleOptions& rules,
                                      std::size_t baseline) {
  const Baseline b = BaselineOf(s, baseline);
  const analysis::PhasedChart c = analysis::ComputePhasedChart(s.values, b.values, 1);
  io::ChartPanel i;
  i.title = s.measurement + ": individuals (I chart), " + std::to_string(s.values.size()) + " " +
            PopulationText(s.population);
  i.x_label = "unit (test order)";
  i.y_label = Axis(s);
  AddSpecLimits(s, i, false);
  const std::vector<double> x = Iota(s.values.size());
  i.series.push_back(Points(s.measurement, x, s.values));
  AddFailMarks(s, x, i);
  if (!c.usable) {
    i.notes.push_back(c.message);
    return {i};
  }
  AddBaselineNotes(b, c, i);
  AddControlLines(c.centre, i, true);
  AddAlarms(NameAlarms(analysis::ApplyRunRules(s.values, c.centre, rules), s, 1), x, s.values, i);
  io::ChartPanel mr;
  mr.title = s.measurement + ": moving range (MR chart), baseline MRbar " + Num(c.spread.centre) +
             ", sigma within = MRbar/1.128 = " + Num(c.sigma_within);
  mr.x_label = "unit (test order)";
  mr.y_label =
      "moving range" + std::string(s.unit.empty() || s.unit == "1" ? "" : " (" + s.unit + ")");
  mr.series.push_back(Points("|x(i) - x(i-1)|", Iota(c.spreads.size(), 2.0), c.spreads));
  AddControlLines(c.spread, mr, false);
  return {i, mr};
}

std::vector<io::ChartPanel> XbarRPanels(const SpcSeries& s, std::size_t n,
                                        const analysis::SpcRuleOptions& rules,
                                        std::size_t baseline) {
  const Baseline b = BaselineOf(s, baseline);
  const analysis::PhasedChart c = analysis::ComputePhasedChart(s.values, b.values, n);
  io::ChartPanel xb;
  xb.title = s.measurement + ": subgroup means (X-bar chart), " + std::to_string(c.points.size()) +
             " subgroups of " + std::to_string(n) + " " + PopulationText(s.population);
  xb.x_label = "subgroup (" + std::to_string(n) + " consecutive units)";
  xb.y_label = Axis(s);
  const std::vector<double> x = Iota(c.points.size());
  xb.series.push_back(Points("subgroup mean", x, c.points));
  if (!c.usable) {
    xb.notes.push_back(c.message);
    return {xb};
  }
  AddBaselineNotes(b, c, xb);
  if (const std::size_t left = s.values.size() % n; left > 0)
    xb.notes.push_back("the last " + std::to_string(left) + " units make no whole subgroup");
  AddControlLines(c.centre, xb, true);
  AddAlarms(NameAlarms(analysis::ApplyRunRules(c.points, c.centre, rules), s, n), x, c.points, xb);
  io::ChartPanel r;
  r.title = s.measurement + ": subgroup ranges (R chart), baseline Rbar " + Num(c.spread.centre) +
            ", sigma within = Rbar/d2 = " + Num(c.sigma_within);
  r.x_label = xb.x_label;
  r.y_label = "range" + std::string(s.unit.empty() || s.unit == "1" ? "" : " (" + s.unit + ")");
  r.series.push_back(Points("max - min", x, c.spreads));
  AddControlLines(c.spread, r, c.spread.lcl > 0.0);
  return {xb, r};
}

io::ChartPanel HistogramPanel(const SpcSeries& s, std::size_t subgroup) {
  io::ChartPanel p;
  p.title = s.measurement + ": histogram of " + std::to_string(s.values.size()) + " " +
            PopulationText(s.population);
  p.x_label = Axis(s);
  p.y_label = "units per bin";
  AddSpecLimits(s, p, true);
  if (!s.values.empty()) {
    auto [lo, hi] = std::minmax_element(s.values.begin(), s.values.end());
    double a = *lo, b = *hi;
    if (!(b > a)) a -= 0.5, b += 0.5;
    const int bins = std::clamp(
        static_cast<int>(std::ceil(std::sqrt(static_cast<double>(s.values.size())))), 5, 30);
    std::vector<double> pass, fail;
    for (std::size_t i = 0; i < s.values.size(); ++i)
      (i < s.failed.size() && s.failed[i] ? fail : pass).push_back(s.values[i]);
    io::ChartBars bars = io::Histogram(pass, a, b, bins);
    bars.label = "PASS units (" + std::to_string(bins) + " bins)";
    p.bars.push_back(bars);
    if (!fail.empty()) {
      io::ChartBars f = io::Histogram(fail, a, b, bins);
      f.label = "FAIL units (" + std::to_string(fail.size()) + ")";
      f.colour = io::kChartOrange;
      p.bars.push_back(f);
    }
  }
  const analysis::CapabilityIndices c =
      analysis::ComputeCapabilityIndices(s.values, s.limit, subgroup);
  auto opt = [](const std::optional<double>& v) { return v ? Num(*v, 3) : std::string("-"); };
  p.notes.push_back("n " + std::to_string(c.sample.n) + " " + PopulationText(s.population) +
                    ", mean " + WithUnit(c.sample.mean, s.unit));
  if (c.sample.n >= 2) {
    p.vlines.push_back(
        Line("mean " + Num(c.sample.mean), c.sample.mean, io::kChartBlue, io::LineStyle::kDotted));
    p.notes.push_back("Cp " + opt(c.cp) + "  Cpk " + opt(c.cpk) + "  (sigma within " +
                      Num(c.sigma_within, 4) + ", " + c.within_method + ")");
    p.notes.push_back("Pp " + opt(c.pp) + "  Ppk " + opt(c.ppk) + "  (overall s " +
                      Num(c.sample.sd, 4) + ")");
  }
  if (!c.caveat.empty()) p.notes.push_back(c.caveat);
  if (!c.message.empty()) p.notes.push_back(c.message);
  return p;
}

}  // namespace

bool ParseChartKind(const std::string& t, ChartKind* out) {
  if (t == "imr") return (*out = ChartKind::kIMr, true);
  if (t == "xbar_r") return (*out = ChartKind::kXbarR, true);
  if (t == "histogram") return (*out = ChartKind::kHistogram, true);
  return false;
}

bool ParsePopulation(const std::string& t, Population* out) {
  if (t == "pass") return (*out = Population::kPass, true);
  if (t == "all") return (*out = Population::kMeasured, true);
  return false;
}

std::string PopulationText(Population p) {
  return p == Population::kPass ? "PASS units" : "PASS and FAIL units";
}

std::string ValidateChartRequest(const ChartRequest& r) {
  if (std::find(analysis::names::kAll.begin(), analysis::names::kAll.end(), r.measurement) ==
      analysis::names::kAll.end()) {
    std::string known;
    for (const auto n : analysis::names::kAll)
      known += (known.empty() ? "" : ", ") + std::string(n);
    return "measurement '" + r.measurement + "' is not one of " + known;
  }
  if (!analysis::SpcConstantsFor(r.subgroup)) return "subgroup must be 2..10";
  std::string why;
  if (!r.rules.IsValid(&why)) return "rules: " + why;
  if (r.from && r.to && !(*r.from < *r.to)) return "from must be before to";
  if (r.baseline < 2) return "baseline must be at least 2 PASS units";
  return "";
}

std::optional<SpcSeries> ReadSpcSeries(db::Store& store, const ChartRequest& req) {
  db::MeasurementQuery q;
  q.from = req.from;
  q.to = req.to;
  q.recipe_hash = req.recipe_hash;
  q.kind = db::RecordKind::kProduction;
  std::vector<db::MeasurementRow> rows = store.MeasurementRows(q);
  std::erase_if(rows, [&](const db::MeasurementRow& r) {
    return r.name != req.measurement || !r.value || r.outcome == analysis::Outcome::kError ||
           r.outcome == analysis::Outcome::kAborted;
  });
  std::stable_sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) {
    return a.started_at != b.started_at ? a.started_at < b.started_at : a.test_id < b.test_id;
  });
  if (rows.empty()) return std::nullopt;
  SpcSeries s;
  s.measurement = req.measurement;
  s.population = req.population;
  const db::MeasurementRow& newest = rows.back();
  s.recipe_hash = newest.recipe_hash;
  s.recipe_id = newest.recipe_id;
  s.recipe_version = newest.recipe_version;
  s.unit = newest.unit;
  s.limit.lo = newest.lo;
  s.limit.hi = newest.hi;
  for (const db::MeasurementRow& r : rows) {
    if (r.recipe_hash != s.recipe_hash) continue;
    if (req.population == Population::kPass && r.outcome != analysis::Outcome::kPass) {
      ++s.left_out_fail;
      continue;
    }
    s.values.push_back(*r.value);
    s.serials.push_back(r.serial);
    s.started_at.push_back(r.started_at);
    s.failed.push_back(r.outcome == analysis::Outcome::kFail);
  }
  if (req.last > 0 && s.values.size() > req.last) {
    const auto drop = static_cast<std::ptrdiff_t>(s.values.size() - req.last);
    s.values.erase(s.values.begin(), s.values.begin() + drop);
    s.serials.erase(s.serials.begin(), s.serials.begin() + drop);
    s.started_at.erase(s.started_at.begin(), s.started_at.begin() + drop);
    s.failed.erase(s.failed.begin(), s.failed.begin() + drop);
  }
  return s;
}

Baseline BaselineOf(const SpcSeries& s, std::size_t baseline) {
  Baseline b;
  std::string first, last;
  for (std::size_t i = 0; i < s.values.size() && b.values.size() < baseline; ++i) {
    if (i < s.failed.size() && s.failed[i]) continue;
    b.values.push_back(s.values[i]);
    if (first.empty()) first = s.serials[i];
    last = s.serials[i];
  }
  b.text = "control limits from the first " + std::to_string(b.values.size()) + " PASS units" +
           (b.values.size() < baseline ? " (all there are; " + std::to_string(baseline) + " asked)"
                                       : std::string()) +
           (first.empty() ? std::string() : ", " + first + ".." + last);
  return b;
}

std::vector<NamedAlarm> NameAlarms(const std::vector<analysis::SpcAlarm>& alarms,
                                   const SpcSeries& s, std::size_t subgroup) {
  const std::size_t n = std::max<std::size_t>(subgroup, 1);
  auto serial = [&](std::size_t unit) { return unit < s.serials.size() ? s.serials[unit] : ""; };
  auto span = [](const char* what, std::size_t a, std::size_t b) {
    return a == b ? std::string(what) + " " + std::to_string(a + 1)
                  : std::string(what) + "s " + std::to_string(a + 1) + "-" + std::to_string(b + 1);
  };
  std::vector<NamedAlarm> out;
  for (const analysis::SpcAlarm& a : alarms) {
    NamedAlarm named;
    named.alarm = a;
    // Units (0-based, in the chart's order) from the run's first point to its last.
    const std::size_t first = a.first * n, last = a.index * n + n - 1;
    named.serial = serial(last);
    named.text = s.measurement + " " + a.message + " at ";
    if (n > 1) named.text += span("subgroup", a.first, a.index) + ", ";
    named.text +=
        span("unit", first, last) + " (serial" +
        (first == last ? " " + named.serial : "s " + serial(first) + ".." + named.serial) + ")";
    out.push_back(std::move(named));
  }
  return out;
}

nlohmann::json AlarmsJson(const std::vector<NamedAlarm>& alarms) {
  nlohmann::json out = nlohmann::json::array();
  for (const NamedAlarm& a : alarms)
    out.push_back({{"rule", a.alarm.rule},
                   {"index", a.alarm.index},
                   {"first", a.alarm.first},
                   {"value", a.alarm.value},
                   {"serial", a.serial},
                   {"message", a.text}});
  return out;
}

std::vector<io::ChartPanel> ChartPanels(const SpcSeries& s, ChartKind kind, std::size_t subgroup,
                                        const analysis::SpcRuleOptions& rules,
                                        std::size_t baseline) {
  switch (kind) {
    case ChartKind::kIMr:
      return ImrPanels(s, rules, baseline);
    case ChartKind::kXbarR:
      return XbarRPanels(s, subgroup, rules, baseline);
    case ChartKind::kHistogram:
      return {HistogramPanel(s, subgroup)};
  }
  return {};
}

io::Chart MeasurementChart(const SpcSeries& s, const ChartRequest& req) {
  io::Chart c;
  c.title = s.measurement + " " + KindName(req.kind, req.subgroup) + " - recipe " + s.recipe_id +
            " v" + std::to_string(s.recipe_version) + " (" + s.recipe_hash.substr(0, 12) + ")";
  if (!s.started_at.empty()) c.title += ", " + s.started_at.front() + " .. " + s.started_at.back();
  // The histogram's within sigma is MRbar/d2: units come one at a time.
  c.panels = ChartPanels(s, req.kind, req.kind == ChartKind::kHistogram ? 1 : req.subgroup,
                         req.rules, req.baseline);
  return c;
}

}  // namespace eol::station
