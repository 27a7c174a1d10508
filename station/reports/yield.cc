#include "station/reports/yield.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <ctime>
#include <set>
#include <stdexcept>

#include "analysis/text.h"

namespace eol::station {
namespace {

using analysis::Outcome;

constexpr std::size_t kMaxShifts = 24;
constexpr std::size_t kMaxShiftName = 16;

bool ValidShiftName(const std::string& name) {
  if (name.empty() || name.size() > kMaxShiftName) return false;
  return std::all_of(name.begin(), name.end(),
                     [](unsigned char c) { return std::isalnum(c) || c == '-' || c == '_'; });
}

// "HH:MM" -> minutes after midnight; -1 when it is not a time of day.
int ParseTimeOfDay(const std::string& text) {
  if (text.size() != 5 || text[2] != ':') return -1;
  for (const std::size_t i : {0u, 1u, 3u, 4u})
    if (!std::isdigit(static_cast<unsigned char>(text[i]))) return -1;
  const int h = (text[0] - '0') * 10 + (text[1] - '0');
  const int m = (text[3] - '0') * 10 + (text[4] - '0');
  return h < 24 && m < 60 ? h * 60 + m : -1;
}

std::string Date(const std::tm& t) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02d", t.tm_year + 1900, t.tm_mon + 1, t.tm_mday);
  return buf;
}

// The local date and minute of day of a stored start time.
struct LocalStart {
  std::tm tm{};
  int minute = 0;
};

LocalStart ToLocal(const std::string& iso, const YieldOptions& o, std::int64_t test_id) {
  std::tm t{};
  char tail = 0;
  if (std::sscanf(iso.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%c", &t.tm_year, &t.tm_mon, &t.tm_mday,
                  &t.tm_hour, &t.tm_min, &t.tm_sec, &tail) != 7 ||
      (tail != '.' && tail != 'Z'))
    throw std::invalid_argument("test " + std::to_string(test_id) + ": started_at '" + iso +
                                "' is not an ISO 8601 UTC time");
  t.tm_year -= 1900;
  t.tm_mon -= 1;
  std::time_t utc = timegm(&t);
  LocalStart out;
  if (o.utc_offset_min) {
    utc += static_cast<std::time_t>(*o.utc_offset_min) * 60;
    gmtime_r(&utc, &out.tm);
  } else {
    localtime_r(&utc, &out.tm);
  }
  out.minute = out.tm.tm_hour * 60 + out.tm.tm_min;
  return out;
}

std::string PreviousDate(std::tm t) {
  t.tm_mday -= 1;
  t.tm_hour = 12;
  t.tm_isdst = 0;
  const std::time_t noon = timegm(&t);
  std::tm prev{};
  gmtime_r(&noon, &prev);
  return Date(prev);
}

std::string RecipeKey(const db::OutcomeRow& r) {
  return r.recipe_id + " v" + std::to_string(r.recipe_version) + " (" +
         r.recipe_hash.substr(0, 12) + ")";
}

// The group of a test: {sort key, key}.
std::pair<std::string, std::string> GroupOf(const db::OutcomeRow& r, const YieldOptions& o,
                                            const std::vector<ShiftStart>& shifts) {
  switch (o.by) {
    case YieldGrouping::kAll:
      return {"", "all"};
    case YieldGrouping::kRecipe:
      return {RecipeKey(r), RecipeKey(r)};
    case YieldGrouping::kDay: {
      const std::string day = Date(ToLocal(r.started_at, o, r.test_id).tm);
      return {day, day};
    }
    case YieldGrouping::kShift:
      break;
  }
  const LocalStart l = ToLocal(r.started_at, o, r.test_id);
  std::size_t i = shifts.size();  // the last shift that started at or before l.minute
  while (i > 0 && shifts[i - 1].minute > l.minute) --i;
  if (i == 0)  // before the first start: the last shift, begun the day before
    return {PreviousDate(l.tm) + " " + std::to_string(100 + shifts.size()),
            PreviousDate(l.tm) + " " + shifts.back().name};
  return {Date(l.tm) + " " + std::to_string(100 + i), Date(l.tm) + " " + shifts[i - 1].name};
}

struct Unit {
  std::string group;  // sort key
  std::size_t tests = 0;
  Outcome first = Outcome::kError, last = Outcome::kError;
  std::optional<Outcome> first_verdict;
};

struct ParetoCount {
  std::size_t tests = 0;
  std::set<std::string> serials;
};
using ParetoCounts = std::map<std::string, ParetoCount>;

void AddUnit(YieldGroup& g, const Unit& u) {
  ++g.units;
  g.first_pass += u.first == Outcome::kPass;
  if (u.first_verdict) {
    ++g.first_verdict_units;
    g.first_verdict_pass += *u.first_verdict == Outcome::kPass;
  }
  g.final_pass += u.last == Outcome::kPass;
  g.final_fail += u.last == Outcome::kFail;
  g.final_open += u.last == Outcome::kError || u.last == Outcome::kAborted;
  g.retested_units += u.tests > 1;
  g.unit_tests += u.tests;
}

std::vector<ParetoEntry> SortedPareto(const ParetoCounts& counts) {
  std::vector<ParetoEntry> out;
  std::size_t total = 0;
  for (const auto& [code, c] : counts) {
    out.push_back({code, c.tests, c.serials.size(), 0.0, 0.0});
    total += c.tests;
  }
  std::sort(out.begin(), out.end(), [](const ParetoEntry& a, const ParetoEntry& b) {
    return a.tests != b.tests ? a.tests > b.tests : a.code < b.code;
  });
  std::size_t running = 0;
  for (ParetoEntry& e : out) {
    running += e.tests;
    e.share = static_cast<double>(e.tests) / static_cast<double>(total);
    e.cumulative = static_cast<double>(running) / static_cast<double>(total);
  }
  return out;
}

nlohmann::json Fraction(std::size_t a, std::size_t b) {
  return b == 0 ? nlohmann::json()
                : nlohmann::json(static_cast<double>(a) / static_cast<double>(b));
}

}  // namespace

bool ParseYieldGrouping(const std::string& text, YieldGrouping* out) {
  for (const YieldGrouping g :
       {YieldGrouping::kAll, YieldGrouping::kShift, YieldGrouping::kDay, YieldGrouping::kRecipe})
    if (text == ToString(g)) {
      *out = g;
      return true;
    }
  return false;
}

const char* ToString(YieldGrouping g) {
  switch (g) {
    case YieldGrouping::kAll:
      return "all";
    case YieldGrouping::kShift:
      return "shift";
    case YieldGrouping::kDay:
      return "day";
    case YieldGrouping::kRecipe:
      return "recipe";
  }
  return "?";
}

bool ParseShifts(const std::string& text, std::vector<ShiftStart>* out, std::string* why) {
  std::vector<ShiftStart> shifts;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find(',', begin), text.size());
    const std::string part = text.substr(begin, end - begin);
    const std::size_t eq = part.find('=');
    const std::string name = part.substr(0, eq);
    const int minute = eq == std::string::npos ? -1 : ParseTimeOfDay(part.substr(eq + 1));
    if (!ValidShiftName(name) || minute < 0) {
      *why = "'" + part +
             "' must be NAME=HH:MM (a name of 1..16 letters, digits, '-' or '_'; a time "
             "00:00..23:59), e.g. " +
             kDefaultShifts;
      return false;
    }
    for (const ShiftStart& s : shifts)
      if (s.name == name || s.minute == minute) {
        *why = "'" + part + "' repeats a name or a start time";
        return false;
      }
    shifts.push_back({name, minute});
    begin = end + 1;
  }
  if (shifts.size() > kMaxShifts) {
    *why = "at most " + std::to_string(kMaxShifts) + " shifts";
    return false;
  }
  std::sort(shifts.begin(), shifts.end(),
            [](const ShiftStart& a, const ShiftStart& b) { return a.minute < b.minute; });
  *out = std::move(shifts);
  return true;
}

std::string ShiftsText(const std::vector<ShiftStart>& shifts) {
  std::string out;
  for (const ShiftStart& s : shifts) {
    char hm[32];
    std::snprintf(hm, sizeof hm, "%02d:%02d", s.minute / 60, s.minute % 60);
    out += (out.empty() ? "" : ",") + s.name + "=" + hm;
  }
  return out;
}

YieldFigures ComputeYield(const std::vector<db::OutcomeRow>& rows, const YieldOptions& options) {
  std::vector<ShiftStart> shifts = options.shifts;
  std::string why;
  if (shifts.empty() && !ParseShifts(kDefaultShifts, &shifts, &why)) throw std::logic_error(why);
  YieldFigures out;
  out.total.key = "all";
  std::map<std::string, YieldGroup> groups;  // by sort key
  std::map<std::string, ParetoCounts> pareto;
  ParetoCounts total_pareto;
  std::map<std::string, Unit> units;
  for (const db::OutcomeRow& r : rows) {
    const auto [sort_key, key] = GroupOf(r, options, shifts);
    YieldGroup& g = groups[sort_key];
    g.key = key;
    for (YieldGroup* x : {&g, &out.total}) {
      ++x->tests;
      ++x->outcomes[r.outcome];
    }
    if (!r.retest_of && !units.count(r.serial)) units[r.serial].group = sort_key;
    const auto unit = units.find(r.serial);
    if (unit == units.end()) {
      ++g.carried_over_tests;
      ++out.total.carried_over_tests;
    } else {
      Unit& u = unit->second;
      if (++u.tests == 1) u.first = r.outcome;
      u.last = r.outcome;
      if (!u.first_verdict && (r.outcome == Outcome::kPass || r.outcome == Outcome::kFail))
        u.first_verdict = r.outcome;
    }
    if (r.outcome == Outcome::kPass) continue;
    const std::string code = r.reasons.empty() ? "none" : analysis::ToString(r.reasons[0].code);
    for (ParetoCounts* p : {&pareto[sort_key], &total_pareto}) {
      ++(*p)[code].tests;
      (*p)[code].serials.insert(r.serial);
    }
  }
  for (const auto& [serial, u] : units) {
    AddUnit(groups[u.group], u);
    AddUnit(out.total, u);
  }
  out.total.pareto = SortedPareto(total_pareto);
  if (options.by == YieldGrouping::kAll) return out;
  for (auto& [sort_key, g] : groups) {
    g.pareto = SortedPareto(pareto[sort_key]);
    out.groups.push_back(std::move(g));
  }
  return out;
}

nlohmann::json ToJson(const YieldGroup& g) {
  nlohmann::json outcomes = nlohmann::json::object();
  for (const Outcome o : analysis::kAllOutcomes)
    outcomes[analysis::ToString(o)] = g.outcomes.count(o) ? g.outcomes.at(o) : 0;
  nlohmann::json pareto = nlohmann::json::array();
  for (const ParetoEntry& e : g.pareto)
    pareto.push_back({{"code", e.code},
                      {"tests", e.tests},
                      {"units", e.units},
                      {"share", e.share},
                      {"cumulative", e.cumulative}});
  return {{"key", g.key},
          {"units", g.units},
          {"first_pass", g.first_pass},
          {"first_pass_yield", Fraction(g.first_pass, g.units)},
          {"first_verdict_units", g.first_verdict_units},
          {"first_verdict_pass", g.first_verdict_pass},
          {"first_verdict_yield", Fraction(g.first_verdict_pass, g.first_verdict_units)},
          {"final_pass", g.final_pass},
          {"final_fail", g.final_fail},
          {"final_open", g.final_open},
          {"final_yield", Fraction(g.final_pass, g.units)},
          {"retested_units", g.retested_units},
          {"unit_tests", g.unit_tests},
          {"tests_per_unit", Fraction(g.unit_tests, g.units)},
          {"tests", g.tests},
          {"carried_over_tests", g.carried_over_tests},
          {"outcomes", outcomes},
          {"pareto", pareto}};
}

namespace {

std::string TimeZoneText(const YieldOptions& o) {
  if (!o.utc_offset_min) return "station local time";
  const int m = *o.utc_offset_min;
  char buf[32];
  std::snprintf(buf, sizeof buf, "UTC%c%02d:%02d", m < 0 ? '-' : '+', std::abs(m) / 60,
                std::abs(m) % 60);
  return buf;
}

nlohmann::json OptText(const std::optional<std::string>& s) {
  return s ? nlohmann::json(*s) : nlohmann::json();
}

}  // namespace

nlohmann::json YieldReport(db::Store& store, const YieldRequest& request) {
  db::OutcomeQuery q;
  q.from = request.from;
  q.to = request.to;
  q.recipe_hash = request.recipe_hash;
  const YieldFigures f = ComputeYield(store.OutcomeRows(q), request.options);
  std::vector<ShiftStart> shifts = request.options.shifts;
  std::string why;
  if (shifts.empty()) ParseShifts(kDefaultShifts, &shifts, &why);
  nlohmann::json groups = nlohmann::json::array();
  for (const YieldGroup& g : f.groups) groups.push_back(ToJson(g));
  return {{"window",
           {{"from", OptText(request.from)},
            {"to", OptText(request.to)},
            {"recipe_hash", OptText(request.recipe_hash)},
            {"by", ToString(request.options.by)},
            {"shifts", ShiftsText(shifts)},
            {"time_zone", TimeZoneText(request.options)}}},
          {"total", ToJson(f.total)},
          {"groups", groups}};
}

namespace {

std::string Percent(const nlohmann::json& v) {
  // "-" where there is nothing to divide by (no unit in the group).
  if (!v.is_number()) return "-";
  return analysis::Percent(v.get<double>(), 1);
}

std::string Row(const nlohmann::json& g) {
  char buf[256], tpu[32] = "-";
  if (g["tests_per_unit"].is_number())
    std::snprintf(tpu, sizeof tpu, "%.2f", g["tests_per_unit"].get<double>());
  std::snprintf(buf, sizeof buf, "%-30s %6zu %9s %9s %9s %5zu %5zu %8zu %9s %6zu\n",
                g["key"].get<std::string>().c_str(), g["units"].get<std::size_t>(),
                Percent(g["first_pass_yield"]).c_str(), Percent(g["first_verdict_yield"]).c_str(),
                Percent(g["final_yield"]).c_str(), g["final_fail"].get<std::size_t>(),
                g["final_open"].get<std::size_t>(), g["retested_units"].get<std::size_t>(), tpu,
                g["tests"].get<std::size_t>());
  return buf;
}

std::string ParetoLine(const nlohmann::json& g) {
  std::string out = "  " + g["key"].get<std::string>() + ":";
  if (g["pareto"].empty()) return out + " no non-PASS test\n";
  for (const auto& e : g["pareto"])
    out += " " + e["code"].get<std::string>() + " " + std::to_string(e["tests"].get<int>()) +
           " tests of " + std::to_string(e["units"].get<int>()) + " units (" + Percent(e["share"]) +
           ", cum. " + Percent(e["cumulative"]) + ");";
  out.back() = '\n';
  return out;
}

}  // namespace

std::string YieldText(const nlohmann::json& r) {
  const nlohmann::json& w = r["window"];
  std::string out = "yield by " + w["by"].get<std::string>() + " (" +
                    w["time_zone"].get<std::string>() + "; shifts " +
                    w["shifts"].get<std::string>() +
                    "); production tests only. first pass: the first test PASSed (an ERROR "
                    "first is not); first verdict: the first PASS/FAIL was PASS; final: the "
                    "last test PASSed; open: the last test was ERROR or ABORTED\n";
  char head[256];
  std::snprintf(head, sizeof head, "%-30s %6s %9s %9s %9s %5s %5s %8s %9s %6s\n", "group", "units",
                "1st pass", "1st verd", "final", "fail", "open", "retested", "per unit", "tests");
  out += head;
  for (const auto& g : r["groups"]) out += Row(g);
  out += Row(r["total"]);
  if (r["total"]["carried_over_tests"].get<std::size_t>() > 0)
    out += std::to_string(r["total"]["carried_over_tests"].get<std::size_t>()) +
           " tests of serials first tested before the window count as tests, not units\n";
  out +=
      "Pareto of the decisive reason of each non-PASS test (tests of units, share, cumulative):\n";
  for (const auto& g : r["groups"]) out += ParetoLine(g);
  out += ParetoLine(r["total"]);
  return out;
}

io::Chart ParetoChart(const nlohmann::json& group, const std::string& title) {
  const nlohmann::json& pareto = group.at("pareto");
  if (pareto.empty())
    throw std::invalid_argument("no non-PASS test in " + group.at("key").get<std::string>() +
                                ": nothing to chart");
  static constexpr std::array kColours = {io::kChartRed,  io::kChartOrange, io::kChartPurple,
                                          io::kChartBlue, io::kChartGreen,  io::kChartGrey};
  io::ChartPanel p;
  p.title = "Pareto of reasons, " + group.at("key").get<std::string>();
  p.x_label = "rank (the legend names each rank's reason code)";
  p.y_label = "% of non-PASS tests";
  io::ChartSeries cumulative;
  cumulative.label = "cumulative %";
  cumulative.colour = io::kChartBlack;
  cumulative.markers = true;
  std::size_t non_pass = 0;
  for (std::size_t i = 0; i < pareto.size(); ++i) {
    const nlohmann::json& e = pareto[i];
    const double x = static_cast<double>(i + 1);
    char label[160];
    std::snprintf(label, sizeof label, "%zu %s: %d tests, %d units (%.0f %%)", i + 1,
                  e["code"].get<std::string>().c_str(), e["tests"].get<int>(),
                  e["units"].get<int>(), 100.0 * e["share"].get<double>());
    p.bars.push_back({label,
                      kColours[i % kColours.size()],
                      {{x - 0.4, x + 0.4, 100.0 * e["share"].get<double>()}}});
    cumulative.x.push_back(x);
    cumulative.y.push_back(100.0 * e["cumulative"].get<double>());
    non_pass += e["tests"].get<std::size_t>();
  }
  p.series.push_back(std::move(cumulative));
  p.hlines.push_back({"80 %", 80.0, io::kChartGrey, io::LineStyle::kDotted, 1.0});
  // At least five ranks wide: whole-number ticks, and one bar is not drawn across the panel.
  p.x_range = {0.5, static_cast<double>(std::max<std::size_t>(pareto.size(), 5)) + 0.5};
  p.y_range = {0.0, 105.0};
  p.notes.push_back(std::to_string(non_pass) + " non-PASS of " +
                    std::to_string(group.at("tests").get<std::size_t>()) +
                    " tests, each under its decisive reason");
  io::Chart chart;
  chart.title = title;
  chart.panels.push_back(std::move(p));
  return chart;
}

}  // namespace eol::station
