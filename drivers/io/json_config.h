// Reading configuration and recipe JSON with errors that name the JSON path and the rule
// broken ("/excitation/f_hi_hz: must be greater than /excitation/f_lo_hz (got 100)").
// Unknown keys are errors too (RejectUnknown), so a typo never silently falls back to a
// default.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace eol::io {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class JsonObject {
 public:
  // `path` is the JSON pointer of `j` ("" for the document root). Throws ConfigError unless
  // j is an object.
  JsonObject(const nlohmann::json& j, std::string path);

  const std::string& path() const { return path_; }
  std::string PathOf(const std::string& key) const { return path_ + "/" + key; }
  bool Has(const std::string& key) const;

  double Number(const std::string& key, double fallback) const;
  double RequiredNumber(const std::string& key) const;
  std::optional<double> OptionalNumber(const std::string& key) const;
  int Integer(const std::string& key, int fallback) const;
  bool Bool(const std::string& key, bool fallback) const;
  std::string String(const std::string& key, const std::string& fallback) const;
  std::string RequiredString(const std::string& key) const;
  std::vector<double> Numbers(const std::string& key, const std::vector<double>& fallback) const;
  JsonObject Object(const std::string& key) const;  // required
  std::optional<JsonObject> OptionalObject(const std::string& key) const;
  const nlohmann::json& Raw(const std::string& key) const;  // required, any type

  // Throws ConfigError naming the first key that no accessor has read.
  void RejectUnknown() const;
  // Throws ConfigError "<path>/<key>: <rule> (got <value>)" unless ok.
  void Require(bool ok, const std::string& key, const std::string& rule) const;

 private:
  const nlohmann::json& At(const std::string& key) const;
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const;

  const nlohmann::json& j_;
  std::string path_;
  mutable std::set<std::string> read_;
};

// Parses a JSON document from text, naming `source` (a file name) and the position of a
// syntax error.
nlohmann::json ParseJsonText(const std::string& text, const std::string& source);
// Reads and parses a file; ConfigError names the file when it cannot be read or parsed.
nlohmann::json ReadJsonFile(const std::string& path);

}  // namespace eol::io
