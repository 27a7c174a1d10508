// The message ParseRecipe throws for a recipe JSON, or "" when it loads (recipe tests).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "drivers/io/json_config.h"
#include "station/daemon/recipe.h"

namespace eol::testing {

inline std::string RecipeErrorOf(const nlohmann::json& j) {
  try {
    station::ParseRecipe(j, "test.json");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace eol::testing
