// The outcome of changing the recipe in use (Station::ChangeRecipe, PUT /api/recipe).
//
// A business result, not a transport one: the HTTP layer (station/daemon/http/recipe_routes.cc)
// alone chooses the status code and the JSON for each kind.
#pragma once

#include <string>

namespace eol::station {

struct RecipeChange {
  enum class Kind {
    kChanged,              // stored, audited and in use for the next test
    kInvalid,              // the recipe does not parse or validate; message names the field
    kNotApproved,          // a proposal (Recipe::approval): an engineer approves it first
    kBusy,                 // a test is running or waiting; nothing changed
    kWrongRecipe,          // another recipe id than the one in use; nothing changed
    kVersionNotIncreased,  // version <= the version in use; nothing changed
    kIoError,              // the file could not be replaced; the old recipe stays in use
  };
  Kind kind = Kind::kInvalid;
  std::string message;  // why, for every kind but kChanged

  // kChanged only: the recipe now in use and the one it replaced.
  std::string id;
  int version = 0;
  std::string hash;
  std::string path;  // the configured recipe file, rewritten
  int previous_version = 0;
  std::string previous_hash;
  std::string kept_as;  // the previous file, kept as <name>.v<previous version>.json
};

}  // namespace eol::station
