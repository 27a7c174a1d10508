// station::ParseRecipe (station/daemon/recipe.h) on JSON text as LoadRecipe and PUT /api/recipe
// give it: a Recipe or io::ConfigError. A Recipe must survive its own round trip (RecipeToJson,
// then ParseRecipe) and keep every whole number as given.
#include "drivers/io/json_config.h"
#include "station/daemon/recipe.h"
#include "tests/fuzz/json_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const nlohmann::json j = eol::io::ParseJsonText(text, "fuzz.json");
    const eol::station::Recipe r = eol::station::ParseRecipe(j, "fuzz.json");
    if (r.hash.size() != 64) eol::fuzz::Finding("ParseRecipe: hash is not 64 hex digits");
    const nlohmann::json emitted = eol::station::RecipeToJson(r);
    eol::fuzz::CheckIntegersKept(j, emitted, "ParseRecipe");
    try {
      eol::station::ParseRecipe(emitted, "round-trip");
    } catch (const eol::io::ConfigError& e) {
      eol::fuzz::Finding(std::string("RecipeToJson of an accepted recipe is refused: ") + e.what());
    }
  } catch (const eol::io::ConfigError&) {
  } catch (...) {
    eol::fuzz::FailOnException("ParseRecipe");
  }
  return 0;
}
