#include "drivers/io/json_config.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>

namespace eol::io {
namespace {

// A value as messages show it: never whole when long (a request body's value can be 4 MB).
std::string Shown(const nlohmann::json& v) {
  std::string text = v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > 200) text = text.substr(0, 200) + "...";
  return text;
}

}  // namespace

JsonObject::JsonObject(const nlohmann::json& j, std::string path) : j_(j), path_(std::move(path)) {
  if (!j_.is_object())
    throw ConfigError((path_.empty() ? std::string("/") : path_) + ": must be a JSON object");
}

bool JsonObject::Has(const std::string& key) const { return j_.contains(key); }

void JsonObject::Fail(const std::string& key, const std::string& what) const {
  throw ConfigError(PathOf(key.size() > 200 ? key.substr(0, 200) + "..." : key) + ": " + what);
}

const nlohmann::json& JsonObject::At(const std::string& key) const {
  read_.insert(key);
  const auto it = j_.find(key);
  if (it == j_.end()) Fail(key, "missing (required)");
  return *it;
}

const nlohmann::json& JsonObject::Raw(const std::string& key) const { return At(key); }

std::optional<double> JsonObject::OptionalNumber(const std::string& key) const {
  read_.insert(key);
  if (!Has(key) || j_.at(key).is_null()) return std::nullopt;
  return RequiredNumber(key);
}

double JsonObject::RequiredNumber(const std::string& key) const {
  const nlohmann::json& v = At(key);
  if (!v.is_number()) Fail(key, "must be a number (got " + Shown(v) + ")");
  const double d = v.get<double>();
  if (!std::isfinite(d)) Fail(key, "must be finite");
  return d;
}

double JsonObject::Number(const std::string& key, double fallback) const {
  read_.insert(key);
  return Has(key) ? RequiredNumber(key) : fallback;
}

int JsonObject::Integer(const std::string& key, int fallback) const {
  read_.insert(key);
  if (!Has(key)) return fallback;
  const nlohmann::json& v = At(key);
  if (!v.is_number_integer()) Fail(key, "must be a whole number (got " + Shown(v) + ")");
  // get<int>() wraps: 4294967300 would be read as 4.
  const bool fits =
      v.is_number_unsigned()
          ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<int>::max())
          : v.get<std::int64_t>() >= std::numeric_limits<int>::min() &&
                v.get<std::int64_t>() <= std::numeric_limits<int>::max();
  if (!fits)
    Fail(key, "must be a whole number in [-2147483648, 2147483647] (got " + Shown(v) + ")");
  return v.get<int>();
}

bool JsonObject::Bool(const std::string& key, bool fallback) const {
  read_.insert(key);
  if (!Has(key)) return fallback;
  const nlohmann::json& v = At(key);
  if (!v.is_boolean()) Fail(key, "must be true or false (got " + Shown(v) + ")");
  return v.get<bool>();
}

std::string JsonObject::RequiredString(const std::string& key) const {
  const nlohmann::json& v = At(key);
  if (!v.is_string()) Fail(key, "must be a string (got " + Shown(v) + ")");
  return v.get<std::string>();
}

std::string JsonObject::String(const std::string& key, const std::string& fallback) const {
  read_.insert(key);
  return Has(key) ? RequiredString(key) : fallback;
}

std::vector<double> JsonObject::Numbers(const std::string& key,
                                        const std::vector<double>& fallback) const {
  read_.insert(key);
  if (!Has(key)) return fallback;
  const nlohmann::json& v = At(key);
  if (!v.is_array()) Fail(key, "must be an array of numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>()))
      Fail(key + "/" + std::to_string(i), "must be a finite number (got " + Shown(v[i]) + ")");
    out.push_back(v[i].get<double>());
  }
  return out;
}

JsonObject JsonObject::Object(const std::string& key) const {
  return JsonObject(At(key), PathOf(key));
}

std::optional<JsonObject> JsonObject::OptionalObject(const std::string& key) const {
  read_.insert(key);
  if (!Has(key)) return std::nullopt;
  return Object(key);
}

void JsonObject::RejectUnknown() const {
  for (auto it = j_.begin(); it != j_.end(); ++it) {
    if (read_.count(it.key())) continue;
    std::string known;
    for (const std::string& k : read_) known += (known.empty() ? "" : ", ") + k;
    Fail(it.key(), "unknown field (known here: " + known + ")");
  }
}

void JsonObject::Require(bool ok, const std::string& key, const std::string& rule) const {
  if (ok) return;
  const auto it = j_.find(key);
  Fail(key, rule + (it != j_.end() ? " (got " + Shown(*it) + ")" : ""));
}

nlohmann::json ParseJsonText(const std::string& text, const std::string& source) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // Not only parse_error: a number beyond double's range ("1e999") is out_of_range.406.
    throw ConfigError(source + ": not valid JSON: " + e.what());
  }
}

nlohmann::json ReadJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return ParseJsonText(text.str(), path);
}

}  // namespace eol::io
