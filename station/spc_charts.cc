#include "station/spc_charts.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "analysis/qc/measurement_names.h"

namespace eol::station {
namespace {

std::string Num(double v, int digits = 6) {
  if (!std::isfinite(v)) return "none";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  return std::string(buf, r.ptr);
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

std::vector<io::ChartPanel> ImrPanels(const SpcSeries& s, const analysis::SpcRuleOptions& rules) {
  const analysis::IMrChart c = analysis::ComputeIMr(s.values);
  io::ChartPanel i;
  i.title = s.measurement + ": individuals (I chart), " + std::to_string(s.values.size()) + " " +
            PopulationText(s.population);
  i.x_label = "unit (test order)";
  i.y_label = Axis(s);
  AddSpecLimits(s, i, false);
  const std::vector<double> x = Iota(s.values.size());
  i.series.push_back(Points(s.measurement, x, s.values));
  if (!c.usable) {
    i.notes.push_back(c.message);
    return {i};
  }
  AddControlLines(c.individuals, i, true);
  AddAlarms(NameAlarms(analysis::ApplyRunRules(s.values, c.individuals, rules), s, 1), x, s.values,
            i);
  io::ChartPanel mr;
  mr.title = s.measurement + ": moving range (MR chart), MRbar " + Num(c.mr_bar) +
             ", sigma within = MRbar/1.128 = " + Num(c.sigma_within);
  mr.x_label = "unit (test order)";
  mr.y_label =
      "moving range" + std::string(s.unit.empty() || s.unit == "1" ? "" : " (" + s.unit + ")");
  mr.series.push_back(
      Points("|x(i) - x(i-1)|", Iota(c.moving_ranges.size(), 2.0), c.moving_ranges));
  AddControlLines(c.moving_range, mr, false);
  return {i, mr};
}

std::vector<io::ChartPanel> XbarRPanels(const SpcSeries& s, std::size_t n,
                                        const analysis::SpcRuleOptions& rules) {
  const analysis::XbarRChart c = analysis::ComputeXbarR(s.values, n);
  io::ChartPanel xb;
  xb.title = s.measurement + ": subgroup means (X-bar chart), " + std::to_string(c.means.size()) +
             " subgroups of " + std::to_string(n) + " " + PopulationText(s.population);
  xb.x_label = "subgroup (" + std::to_string(n) + " consecutive units)";
  xb.y_label = Axis(s);
  AddSpecLimits(s, xb, false);
  const std::vector<double> x = Iota(c.means.size());
  xb.series.push_back(Points("subgroup mean", x, c.means));
  if (!c.usable) {
    xb.notes.push_back(c.message);
    return {xb};
  }
  if (!c.message.empty()) xb.notes.push_back(c.message);
  AddControlLines(c.xbar, xb, true);
  AddAlarms(NameAlarms(analysis::ApplyRunRules(c.means, c.xbar, rules), s, n), x, c.means, xb);
  io::ChartPanel r;
  r.title = s.measurement + ": subgroup ranges (R chart), Rbar " + Num(c.r_bar) +
            ", sigma within = Rbar/d2 = " + Num(c.sigma_within);
  r.x_label = xb.x_label;
  r.y_label = "range" + std::string(s.unit.empty() || s.unit == "1" ? "" : " (" + s.unit + ")");
  r.series.push_back(Points("max - min", x, c.ranges));
  AddControlLines(c.range, r, c.range.lcl > 0.0);
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
    io::ChartBars bars = io::Histogram(s.values, a, b, bins);
    bars.label = s.measurement + " (" + std::to_string(bins) + " bins)";
    p.bars.push_back(bars);
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
  }
  if (req.last > 0 && s.values.size() > req.last) {
    const auto drop = static_cast<std::ptrdiff_t>(s.values.size() - req.last);
    s.values.erase(s.values.begin(), s.values.begin() + drop);
    s.serials.erase(s.serials.begin(), s.serials.begin() + drop);
    s.started_at.erase(s.started_at.begin(), s.started_at.begin() + drop);
  }
  return s;
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
                                        const analysis::SpcRuleOptions& rules) {
  switch (kind) {
    case ChartKind::kIMr:
      return ImrPanels(s, rules);
    case ChartKind::kXbarR:
      return XbarRPanels(s, subgroup, rules);
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
  c.panels =
      ChartPanels(s, req.kind, req.kind == ChartKind::kHistogram ? 1 : req.subgroup, req.rules);
  return c;
}

}  // namespace eol::station
