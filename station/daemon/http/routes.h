// The API's routes by resource (the list with their contracts is in station/daemon/http_api.h), and
// the mapping of the station's typed results to HTTP statuses and JSON.
#pragma once

#include "station/daemon/http/context.h"
#include "station/daemon/http/reply.h"
#include "station/daemon/qc_service.h"
#include "station/daemon/recipe_change.h"

namespace eol::station::http {

// GET /api/status, GET /api/events, GET /metrics, GET /, GET /engineer and /static
// (station/daemon/http/board_routes.cc)
void AddBoardRoutes(httplib::Server& s, ApiContext& c);
// GET /api/recipe, PUT /api/recipe, GET /api/recipe/audit, POST /api/recipe/approve
// (station/daemon/http/recipe_routes.cc)
void AddRecipeRoutes(httplib::Server& s, ApiContext& c);
// GET /api/units/{serial}, GET /api/tests/{id}, GET /api/tests, POST /api/tests
void AddTestRoutes(httplib::Server& s, ApiContext& c);
// GET /api/stats, GET /api/charts/{measurement}.svg, GET /api/detectability, POST /api/teach
// (station/daemon/http/qc_routes.cc)
void AddQcRoutes(httplib::Server& s, ApiContext& c);
// GET and POST /api/units/{serial}/teardown, GET /api/teardown/review,
// GET /api/units/{serial}/report.pdf (station/daemon/http/teardown_routes.cc)
void AddTeardownRoutes(httplib::Server& s, ApiContext& c);
// POST /api/pod.svg, POST /api/gap.svg (station/daemon/http/figure_routes.cc)
void AddFigureRoutes(httplib::Server& s, ApiContext& c);

// kChanged: 200 with {id, version, hash, path, previous: {version, hash, kept_as}};
// kInvalid: 400 "invalid_recipe"; kBusy: 409 "busy"; kWrongRecipe: 409 "wrong_recipe";
// kVersionNotIncreased: 409 "version_not_increased"; kIoError: 500 "recipe_not_written".
HttpReply RecipeChangeReply(const RecipeChange& change);

// kProposed: 200 with the report; kNotUsable: 422 with the report (it says why);
// kBadSerial: 400 "bad_serial"; kInvalidRecipe: 422 "invalid_recipe".
HttpReply TeachReply(const TeachResult& result);

}  // namespace eol::station::http
