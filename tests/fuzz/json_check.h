// A check for the JSON readers: every whole number the document gives must be the value the
// reader kept. Compared through the reader's own emitter (RecipeToJson) or by the caller.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "tests/fuzz/fuzz_support.h"

namespace eol::fuzz {

// For every integer leaf of `given` whose JSON pointer also holds a number in `kept`, the two
// must be equal (a wrapped or truncated integer is a finding).
inline void CheckIntegersKept(const nlohmann::json& given, const nlohmann::json& kept,
                              const std::string& reader) {
  const nlohmann::json flat_given = given.flatten();
  const nlohmann::json flat_kept = kept.flatten();
  for (auto it = flat_given.begin(); it != flat_given.end(); ++it) {
    if (!it->is_number_integer()) continue;
    const auto k = flat_kept.find(it.key());
    if (k == flat_kept.end() || !k->is_number()) continue;
    // Integers compare by their text (signed and unsigned alike), others as doubles.
    const bool equal =
        k->is_number_integer() ? k->dump() == it->dump() : k->get<double>() == it->get<double>();
    if (!equal)
      Finding(reader + ": " + it.key() + " was given as " + it->dump() + " but kept as " +
              k->dump());
  }
}

}  // namespace eol::fuzz
