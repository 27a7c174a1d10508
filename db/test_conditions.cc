#include "db/test_conditions.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <utility>

#include "analysis/qc/measurement_names.h"

namespace eol::db {
namespace {

using nlohmann::json;

// The key prefixes of PairLooks, followed by the pair's suffix.
constexpr std::string_view kLooks = "looks";
constexpr std::string_view kUndecided = "undecided";

// The one list of the scalar fields and their keys, for writing (const) and reading.
template <class Conditions, class Visit>
void ForEachField(Conditions& c, Visit&& f) {
  f(analysis::names::kClampPressureBar, c.clamp_pressure_bar);
  f("phase_pair", c.phase_pair);
  f("excitation_peak_v", c.excitation_peak_v);
  f("crest_factor", c.crest_factor);
  f("line_spacing_hz", c.line_spacing_hz);
  f("sample_rate_hz", c.sample_rate_hz);
  f("clamp_pressure_min_bar", c.clamp_pressure_min_bar);
  f("clamp_pressure_max_bar", c.clamp_pressure_max_bar);
  f("watchdog_max_gap_ms", c.watchdog_max_gap_ms);
  f("analysis_overlapped_s", c.analysis_overlapped_s);
  f("periods_used", c.periods_used);
  f("excitation_v_rms", c.excitation_v_rms);
  f("excitation_a_rms", c.excitation_a_rms);
  f("winding_temperature_c", c.winding_temperature_c);
  f("conditions_in_window", c.conditions_in_window);
  f("simulation", c.simulation);
  f("variant", c.variant);
  f("variant_by", c.variant_by);
}

// JSON has no NaN or infinity: such a value is written as null (as nlohmann dumps it).
json Value(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
template <class T>
json Value(const T& v) {
  return v;
}

// Each sets the field and returns true only when `v` has the field's type.
bool Take(const json& v, std::optional<double>& f) {
  if (!v.is_number()) return false;
  f = v.get<double>();
  return true;
}

template <class Int>
bool TakeInteger(const json& v, std::optional<Int>& f, std::int64_t lo, std::uint64_t hi) {
  if (v.is_number_unsigned()) {
    if (v.get<std::uint64_t>() > hi) return false;
  } else if (!v.is_number_integer() || v.get<std::int64_t>() < lo) {
    return false;
  }
  f = v.get<Int>();
  return true;
}

bool Take(const json& v, std::optional<int>& f) {
  return TakeInteger(v, f, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
}

bool Take(const json& v, std::optional<std::size_t>& f) {
  return TakeInteger(v, f, 0, std::numeric_limits<std::size_t>::max());
}

bool Take(const json& v, std::optional<bool>& f) {
  if (!v.is_boolean()) return false;
  f = v.get<bool>();
  return true;
}

bool Take(const json& v, std::optional<std::string>& f) {
  if (!v.is_string()) return false;
  f = v.get<std::string>();
  return true;
}

bool Take(const json& v, std::optional<std::vector<std::string>>& f) {
  if (!v.is_array()) return false;
  for (const json& e : v)
    if (!e.is_string()) return false;
  f = v.get<std::vector<std::string>>();
  return true;
}

// The pair suffix of `key` when it is `prefix` alone or `prefix@...`.
std::optional<std::string> PairSuffix(std::string_view key, std::string_view prefix) {
  if (!key.starts_with(prefix)) return std::nullopt;
  const std::string_view rest = key.substr(prefix.size());
  if (!rest.empty() && rest.front() != '@') return std::nullopt;
  return std::string(rest);
}

// Moves every "looks<suffix>" / "undecided<suffix>" of the right type from `extra` to `looks`.
void TakeLooks(json& extra, std::map<std::string, PairLooks>& looks) {
  for (auto it = extra.begin(); it != extra.end();) {
    bool taken = false;
    if (const auto s = PairSuffix(it.key(), kLooks)) {
      std::optional<int> n;
      if ((taken = Take(it.value(), n))) looks[*s].looks = n;
    } else if (const auto u = PairSuffix(it.key(), kUndecided)) {
      std::optional<std::vector<std::string>> names;
      if ((taken = Take(it.value(), names))) looks[*u].undecided = std::move(names);
    }
    it = taken ? extra.erase(it) : std::next(it);
  }
}

}  // namespace

void to_json(json& j, const TestConditions& c) {
  j = c.extra.is_object() ? c.extra : json::object();
  ForEachField(c, [&j](std::string_view key, const auto& field) {
    if (field) j[std::string(key)] = Value(*field);
  });
  for (const auto& [suffix, pair] : c.looks) {
    if (pair.looks) j[std::string(kLooks) + suffix] = *pair.looks;
    if (pair.undecided) j[std::string(kUndecided) + suffix] = *pair.undecided;
  }
}

void from_json(const json& j, TestConditions& c) {
  c = TestConditions{};
  if (j.is_null()) return;
  if (!j.is_object())
    throw json::type_error::create(
        302, "conditions: must be an object, not " + std::string(j.type_name()), &j);
  c.extra = j;
  ForEachField(c, [&c](std::string_view key, auto& field) {
    const auto it = c.extra.find(std::string(key));
    if (it != c.extra.end() && Take(*it, field)) c.extra.erase(it);
  });
  TakeLooks(c.extra, c.looks);
}

}  // namespace eol::db
