// Variants (issue 36): one station, several approved recipes, one picked per unit.
//
// The station config lists them instead of the single "recipe" (both at once are refused):
//
//   "variants": [
//     {"name": "P10", "recipe": "../recipes/pmsm-10pole.json", "plc_code": 1,
//      "prefixes": ["P10-"], "patterns": ["10P[0-9]{6}"]},
//     {"name": "P8H", "recipe": "pmsm-8pole-heavy.json", "plc_code": 2, "prefixes": ["P8H-"]}]
//
//   name      what the operator picks and every record names (conditions "variant"): 1 to 32
//             characters from A-Z a-z 0-9 and "-_.", unique
//   recipe    the recipe file (relative to the config); it must load and be approved
//             (station/daemon/recipe.h RecipeApproval): a proposal stops the station at start,
//             naming the variant and the file. Each recipe id at most once.
//   plc_code  1..65535, the value the line PLC writes into its "variant" holding register
//             (station/daemon/plc/plc_map.h); optional (without it the PLC cannot pick this
//             variant), unique
//   prefixes  part-number prefixes of the serial (the scanned code): "P10-" picks this variant
//             for "P10-000123". A prefix may not begin another variant's prefix (ambiguous).
//   patterns  regular expressions (PCRE2, Perl syntax) the WHOLE serial must match (anchored
//             at both ends); each at most 200 characters. A match is bounded (kPatternMatchLimit
//             steps): a pattern that backtracks beyond it ("(a+)+b") refuses the unit naming
//             the pattern, it never hangs the station nor counts as "no match"
//
// Selection per unit (SelectVariant), from what the request names and the serial:
//   - the request names a variant: the operator's choice by name (POST /api/tests "variant"),
//     or the PLC's variant register (0: none). An unknown name or code is refused.
//   - otherwise the serial's rules decide: exactly one variant's prefix or pattern must match.
//   - a named variant that another variant's rule claims for this serial is refused as a
//     conflict: a mislabelled part is never tested with the other type's recipe.
//   - nothing named and no rule matching (or rules of two variants matching): refused.
// Refused means nothing is started, clamped or excited, and nothing is stored; the reason
// names the serial, the choice and the rules. There is no default variant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace eol::station {

inline constexpr std::size_t kMaxVariantNameChars = 32;
inline constexpr std::size_t kMaxVariantPatternChars = 200;
inline constexpr std::uint32_t kPatternMatchLimit = 100000;  // PCRE2 match limit per serial

struct CompiledPattern;  // PCRE2 code, private to variants.cc

struct VariantConfig {
  std::string name;
  std::string recipe_path;     // resolved against the config's folder
  std::uint16_t plc_code = 0;  // 0: the PLC cannot pick it
  std::vector<std::string> prefixes;
  std::vector<std::string> patterns;                             // as written
  std::vector<std::shared_ptr<const CompiledPattern>> compiled;  // the patterns, compiled once
};

// The "variants" array at JSON pointer `path`; recipe paths resolved by `resolve`. Throws
// io::ConfigError naming the JSON path ("/variants/1/plc_code: ...").
std::vector<VariantConfig> ParseVariants(const nlohmann::json& list, const std::string& path,
                                         const std::function<std::string(std::string)>& resolve);

// What a start request says about its variant (station/daemon/test_request.h TestRequest).
struct VariantChoice {
  std::string name;            // the operator's choice; empty: none
  std::uint16_t plc_code = 0;  // the PLC's variant register; 0: none
};

enum class VariantRefusal {
  kNone,
  kUnknown,   // the name or the PLC code names no variant of this station
  kNoRule,    // nothing named, and no variant's rule (or more than one's) matches the serial,
              // or a pattern exceeded its match limit on it
  kConflict,  // the named variant is not the one the serial's rule gives
};
// "unknown_variant", "no_variant", "variant_conflict": the HTTP error code.
const char* ToString(VariantRefusal r);

struct VariantSelection {
  VariantRefusal refusal = VariantRefusal::kNone;
  std::size_t index = 0;  // into the variants, when not refused
  std::string by;         // how it was picked: "operator", "plc code 2", "prefix 'P10-'", ...
  std::string why;        // when refused: the reason, naming serial, choice and rules
};

VariantSelection SelectVariant(const std::vector<VariantConfig>& variants,
                               const std::string& serial, const VariantChoice& choice);

// For GET /api/variants: [{"name", "plc_code" (null when none), "prefixes", "patterns"}].
nlohmann::json VariantsJson(const std::vector<VariantConfig>& variants);

}  // namespace eol::station
