#include "station/daemon/variants.h"

#include <algorithm>
#include <functional>

#include "drivers/io/json_config.h"

#define PCRE2_CODE_UNIT_WIDTH 8
#include <pcre2.h>

namespace eol::station {

struct CompiledPattern {
  pcre2_code* code = nullptr;
  ~CompiledPattern() { pcre2_code_free(code); }
};

namespace {

// The pattern compiled to match whole serials; throws io::ConfigError at `at` when it is none.
std::shared_ptr<const CompiledPattern> Compile(const std::string& pattern, const std::string& at) {
  int error = 0;
  PCRE2_SIZE offset = 0;
  auto p = std::make_shared<CompiledPattern>();
  p->code = pcre2_compile(reinterpret_cast<PCRE2_SPTR>(pattern.data()), pattern.size(),
                          PCRE2_ANCHORED | PCRE2_ENDANCHORED, &error, &offset, nullptr);
  if (p->code == nullptr) {
    PCRE2_UCHAR text[256];
    pcre2_get_error_message(error, text, sizeof text);
    throw io::ConfigError(at + ": not a regular expression (" +
                          std::string(reinterpret_cast<const char*>(text)) + " at offset " +
                          std::to_string(offset) + ")");
  }
  return p;
}

enum class Match { kNo, kYes, kTooCostly };

Match MatchWhole(const CompiledPattern& p, const std::string& serial) {
  const std::unique_ptr<pcre2_match_data, decltype(&pcre2_match_data_free)> data(
      pcre2_match_data_create_from_pattern(p.code, nullptr), pcre2_match_data_free);
  const std::unique_ptr<pcre2_match_context, decltype(&pcre2_match_context_free)> context(
      pcre2_match_context_create(nullptr), pcre2_match_context_free);
  if (!data || !context) return Match::kTooCostly;
  pcre2_set_match_limit(context.get(), kPatternMatchLimit);
  pcre2_set_depth_limit(context.get(), kPatternMatchLimit);
  const int rc = pcre2_match(p.code, reinterpret_cast<PCRE2_SPTR>(serial.data()), serial.size(), 0,
                             0, data.get(), context.get());
  if (rc >= 0) return Match::kYes;
  return rc == PCRE2_ERROR_NOMATCH ? Match::kNo : Match::kTooCostly;
}

bool ValidName(const std::string& s) {
  return !s.empty() && s.size() <= kMaxVariantNameChars &&
         s.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_.") ==
             std::string::npos;
}

// An optional array of non-empty strings of at most `max_chars`.
std::vector<std::string> Strings(const io::JsonObject& o, const std::string& key,
                                 std::size_t max_chars) {
  std::vector<std::string> out;
  if (!o.Has(key)) return out;
  const nlohmann::json& list = o.Raw(key);
  if (!list.is_array()) throw io::ConfigError(o.PathOf(key) + ": must be an array of strings");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string at = o.PathOf(key) + "/" + std::to_string(i);
    if (!list[i].is_string() || list[i].get<std::string>().empty())
      throw io::ConfigError(at + ": must be a non-empty string");
    if (list[i].get<std::string>().size() > max_chars)
      throw io::ConfigError(at + ": at most " + std::to_string(max_chars) + " characters");
    out.push_back(list[i].get<std::string>());
  }
  return out;
}

VariantConfig ParseOne(const io::JsonObject& o,
                       const std::function<std::string(std::string)>& resolve) {
  VariantConfig v;
  v.name = o.RequiredString("name");
  o.Require(ValidName(v.name), "name", "must be 1 to 32 characters from A-Z a-z 0-9 and \"-_.\"");
  v.recipe_path = resolve(o.RequiredString("recipe"));
  if (o.Has("plc_code")) {
    const int code = o.Integer("plc_code", 0);
    o.Require(code >= 1 && code <= 65535, "plc_code",
              "must be in [1, 65535] (the PLC's variant register; 0 there means none)");
    v.plc_code = static_cast<std::uint16_t>(code);
  }
  v.prefixes = Strings(o, "prefixes", 64);  // a serial is at most 64 characters
  v.patterns = Strings(o, "patterns", kMaxVariantPatternChars);
  for (std::size_t i = 0; i < v.patterns.size(); ++i)
    v.compiled.push_back(Compile(v.patterns[i], o.PathOf("patterns") + "/" + std::to_string(i)));
  o.RejectUnknown();
  return v;
}

// Names, codes and prefixes must each single out one variant.
void CheckDistinct(const std::vector<VariantConfig>& vs, std::size_t k, const std::string& at) {
  const VariantConfig& v = vs[k];
  for (std::size_t i = 0; i < k; ++i) {
    const VariantConfig& w = vs[i];
    if (w.name == v.name)
      throw io::ConfigError(at + "/name: '" + v.name + "' is already variant " + std::to_string(i) +
                            "'s name");
    if (v.plc_code != 0 && w.plc_code == v.plc_code)
      throw io::ConfigError(at + "/plc_code: " + std::to_string(v.plc_code) +
                            " is already variant '" + w.name + "''s code");
    for (std::size_t p = 0; p < v.prefixes.size(); ++p)
      for (const std::string& q : w.prefixes)
        if (v.prefixes[p].rfind(q, 0) == 0 || q.rfind(v.prefixes[p], 0) == 0)
          throw io::ConfigError(at + "/prefixes/" + std::to_string(p) + ": '" + v.prefixes[p] +
                                "' and variant '" + w.name + "''s prefix '" + q +
                                "' would both match a serial starting with the longer one");
  }
}

// The rule of `v` that claims `serial`, or "" when none does; `costly` gets a pattern that
// exceeded its match limit.
std::string MatchingRule(const VariantConfig& v, const std::string& serial, std::string* costly) {
  for (const std::string& p : v.prefixes)
    if (serial.rfind(p, 0) == 0) return "prefix '" + p + "'";
  for (std::size_t i = 0; i < v.compiled.size(); ++i) {
    const Match m = MatchWhole(*v.compiled[i], serial);
    if (m == Match::kYes) return "pattern '" + v.patterns[i] + "'";
    if (m == Match::kTooCostly && costly->empty())
      *costly = "variant '" + v.name + "''s pattern '" + v.patterns[i] + "'";
  }
  return "";
}

std::string Names(const std::vector<VariantConfig>& vs) {
  std::string s;
  for (const VariantConfig& v : vs) s += (s.empty() ? "" : ", ") + v.name;
  return s;
}

std::string Codes(const std::vector<VariantConfig>& vs) {
  std::string s;
  for (const VariantConfig& v : vs)
    if (v.plc_code != 0) s += (s.empty() ? "" : ", ") + std::to_string(v.plc_code) + " " + v.name;
  return s.empty() ? "none configured" : s;
}

VariantSelection Refused(VariantRefusal kind, std::string why) {
  VariantSelection s;
  s.refusal = kind;
  s.why = std::move(why);
  return s;
}

}  // namespace

std::vector<VariantConfig> ParseVariants(const nlohmann::json& list, const std::string& path,
                                         const std::function<std::string(std::string)>& resolve) {
  if (!list.is_array() || list.empty())
    throw io::ConfigError(path + ": must be a non-empty array of variants");
  std::vector<VariantConfig> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string at = path + "/" + std::to_string(i);
    out.push_back(ParseOne(io::JsonObject(list[i], at), resolve));
    CheckDistinct(out, i, at);
  }
  return out;
}

const char* ToString(VariantRefusal r) {
  switch (r) {
    case VariantRefusal::kNone:
      return "none";
    case VariantRefusal::kUnknown:
      return "unknown_variant";
    case VariantRefusal::kNoRule:
      return "no_variant";
    case VariantRefusal::kConflict:
      return "variant_conflict";
  }
  return "?";
}

VariantSelection SelectVariant(const std::vector<VariantConfig>& variants,
                               const std::string& serial, const VariantChoice& choice) {
  std::optional<std::size_t> named;
  std::string by;
  if (!choice.name.empty()) {
    const auto it = std::find_if(variants.begin(), variants.end(),
                                 [&](const VariantConfig& v) { return v.name == choice.name; });
    if (it == variants.end())
      return Refused(VariantRefusal::kUnknown, "unknown variant '" + choice.name +
                                                   "' (this station's: " + Names(variants) + ")");
    named = static_cast<std::size_t>(it - variants.begin());
    by = "operator";
  }
  if (choice.plc_code != 0) {
    const auto it = std::find_if(variants.begin(), variants.end(), [&](const VariantConfig& v) {
      return v.plc_code == choice.plc_code;
    });
    if (it == variants.end())
      return Refused(VariantRefusal::kUnknown,
                     "the PLC's variant register holds " + std::to_string(choice.plc_code) +
                         ", no variant's code (codes: " + Codes(variants) + ")");
    const auto index = static_cast<std::size_t>(it - variants.begin());
    if (named && *named != index)
      return Refused(VariantRefusal::kConflict, "the operator chose variant '" + choice.name +
                                                    "', the PLC's register " + it->name);
    named = index;
    by = "plc code " + std::to_string(choice.plc_code);
  }
  std::vector<std::pair<std::size_t, std::string>> claims;  // variant, rule
  std::string costly;
  for (std::size_t i = 0; i < variants.size(); ++i)
    if (std::string rule = MatchingRule(variants[i], serial, &costly); !rule.empty())
      claims.emplace_back(i, std::move(rule));
  // Whether it would have matched is unknown: neither a choice nor another rule may stand.
  if (!costly.empty())
    return Refused(VariantRefusal::kNoRule, costly + " exceeded its match limit on serial '" +
                                                serial +
                                                "' (it backtracks too much); simplify the pattern");
  std::string claimed;
  for (const auto& [i, rule] : claims)
    claimed += (claimed.empty() ? "" : ", ") + variants[i].name + " by its " + rule;
  VariantSelection s;
  if (named) {
    for (const auto& [i, rule] : claims)
      if (i != *named)
        return Refused(VariantRefusal::kConflict,
                       "serial '" + serial + "' is part number of variant " + claimed +
                           ", but variant '" + variants[*named].name + "' was chosen (" + by +
                           "); check the part and the choice");
    s.index = *named;
    s.by = by;
    return s;
  }
  if (claims.empty())
    return Refused(VariantRefusal::kNoRule,
                   "serial '" + serial +
                       "' matches no variant's part-number prefix or pattern and no variant was "
                       "chosen (variants: " +
                       Names(variants) + "); choose the variant or check the serial");
  if (claims.size() > 1)
    return Refused(VariantRefusal::kNoRule, "serial '" + serial + "' matches several variants (" +
                                                claimed + "); choose the variant");
  s.index = claims.front().first;
  s.by = claims.front().second;
  return s;
}

nlohmann::json VariantsJson(const std::vector<VariantConfig>& variants) {
  nlohmann::json list = nlohmann::json::array();
  for (const VariantConfig& v : variants)
    list.push_back({{"name", v.name},
                    {"plc_code", v.plc_code == 0 ? nlohmann::json() : nlohmann::json(v.plc_code)},
                    {"prefixes", v.prefixes},
                    {"patterns", v.patterns}});
  return list;
}

}  // namespace eol::station
