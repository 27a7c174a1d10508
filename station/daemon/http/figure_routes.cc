// Figures from an engineer's files, drawn by the code the command uses (one drawing, no copy):
//
//   POST /api/pod.svg  {"hits_csv": "<text>", "name", "link", "scale", "confidence",
//                       "pod_level", "f0_limits_hz": [...]}
//       the POD figure of `eol pod --hits FILE --pod-svg OUT` (station/reports/pod_chart.h): the
//       hits CSV as text, optional name (default "hits.csv"), the fit's options as `eol pod` takes
//       them, up to 10 f0 limits (Hz) to draw.
//   POST /api/gap.svg  {"simulation": {"name", "text"}, "measured": [{"name", "text"}, ...],
//                       "quantity", "f_lo_hz", "f_hi_hz", "sigma_pool", "inertia_kg_m2",
//                       "effects": [...], "pairs"}
//       the plot of `eol gap --sim FILE --measured FILE... --plot OUT`
//       (station/reports/gap_diagnosis.h): each input is the text of a file `eol gap` reads, its
//       name giving the format (.zma, .json; otherwise CSV); 1 to 8 measured units; J_r defaults to
//       the recipe in use; "pairs": false is --no-pairs.
//
// Both answer image/svg+xml. Bodies up to kMaxUploadBytes; an unknown field, a wrong type or
// value is 400 "bad_request" naming it; an input the readers refuse is 400 "bad_hits" or
// "bad_input" with the reader's message (file, line and column by the upload's name); a gap
// diagnosis that cannot be used is 422 "not_usable". The figures change nothing, but cost
// CPU: with http.tokens configured only engineers may ask; a station without tokens (loopback
// only) serves them to anyone on it, as it does its operator routes.
#include <cmath>
#include <set>
#include <sstream>

#include "drivers/io/chart.h"
#include "drivers/io/file_error.h"
#include "drivers/io/json_config.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http/routes.h"
#include "station/reports/gap_diagnosis.h"
#include "station/reports/pod_chart.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

using nlohmann::json;

ApiError BadRequest(std::string message) {
  return {ApiErrorKind::kBadRequest, "bad_request", std::move(message)};
}

// A body field of the wrong type or out of range; thrown inside the handlers' parsing.
struct BadField {
  std::string message;
};

std::optional<ApiError> EngineerWhenTokens(const ApiContext& c, const httplib::Request& req) {
  if (c.options.tokens.empty()) return std::nullopt;
  const auto who = RequireRole(req, c.options.tokens, Role::kEngineer, "draw figures");
  if (const ApiError* e = std::get_if<ApiError>(&who)) return *e;
  return std::nullopt;
}

// The body as a JSON object whose keys are all in `known`.
std::variant<json, ApiError> ObjectBody(const httplib::Request& req,
                                        const std::set<std::string>& known) {
  auto parsed = ParseBody(req, kMaxUploadBytes);
  if (std::holds_alternative<ApiError>(parsed)) return parsed;
  const json& body = std::get<json>(parsed);
  if (!body.is_object()) return BadRequest("the body must be a JSON object");
  for (const auto& [key, value] : body.items())
    if (!known.count(key)) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      return BadRequest("unknown field '" + (key.size() > 100 ? key.substr(0, 100) + "..." : key) +
                        "' (" + list + ")");
    }
  return parsed;
}

std::string Text(const json& body, const std::string& key, const std::string& fallback,
                 std::size_t max_size = 128) {
  if (!body.contains(key)) return fallback;
  const json& v = body.at(key);
  if (!v.is_string()) throw BadField{key + ": must be a string"};
  const std::string s = v.get<std::string>();
  if (s.empty() || s.size() > max_size)
    throw BadField{key + ": must be 1 to " + std::to_string(max_size) + " characters"};
  return s;
}

double Number(const json& body, const std::string& key, double fallback, double lo, double hi) {
  if (!body.contains(key)) return fallback;
  const json& v = body.at(key);
  if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi)) {
    std::ostringstream range;
    range << key << ": must be a number in [" << lo << ", " << hi << "] (have " << Excerpt(v)
          << ")";
    throw BadField{range.str()};
  }
  return v.get<double>();
}

const json& Array(const json& body, const std::string& key, std::size_t lo, std::size_t hi) {
  const json& v = body.at(key);
  if (!v.is_array() || v.size() < lo || v.size() > hi)
    throw BadField{key + ": must be an array of " + std::to_string(lo) + " to " +
                   std::to_string(hi) + " entries"};
  return v;
}

void PostPodSvg(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  if (const auto e = EngineerWhenTokens(c, req)) return Send(res, *e);
  const auto parsed = ObjectBody(
      req, {"hits_csv", "name", "link", "scale", "confidence", "pod_level", "f0_limits_hz"});
  if (const ApiError* e = std::get_if<ApiError>(&parsed)) return Send(res, *e);
  const json& body = std::get<json>(parsed);
  if (!body.contains("hits_csv") || !body["hits_csv"].is_string())
    return Send(res, BadRequest("hits_csv: required, the text of the hits CSV (columns size, "
                                "hit; optional class, f0_hz)"));
  std::string name;
  analysis::PodOptions options;
  std::vector<F0Limit> limits;
  try {
    name = Text(body, "name", "hits.csv");
    options.link = analysis::ParsePodLink(Text(body, "link", "logit"));
    options.scale = analysis::ParsePodScale(Text(body, "scale", "linear"));
    options.confidence = Number(body, "confidence", options.confidence, 0.5, 0.999);
    options.pod_level = Number(body, "pod_level", options.pod_level, 0.5, 0.999);
    if (body.contains("f0_limits_hz"))
      for (const json& f : Array(body, "f0_limits_hz", 0, 10)) {
        if (!f.is_number() || !(f.get<double>() > 0.0 && f.get<double>() <= 1e5))
          throw BadField{"f0_limits_hz: each must be a number in (0, 100000] Hz (have " +
                         Excerpt(f) + ")"};
        limits.push_back({"f0 limit", f.get<double>()});
      }
  } catch (const BadField& e) {
    return Send(res, BadRequest(e.message));
  } catch (const std::invalid_argument& e) {  // ParsePodLink, ParsePodScale
    return Send(res, BadRequest(e.what()));
  }
  std::string why;
  if (!options.IsValid(&why)) return Send(res, BadRequest(why));
  HitsTable hits;
  try {
    std::istringstream in(body["hits_csv"].get<std::string>());
    hits = ParseHits(in, name);
  } catch (const std::runtime_error& e) {
    return Send(res, ApiError{ApiErrorKind::kBadRequest, "bad_hits", e.what()});
  }
  res.status = 200;
  res.set_content(PodSvg("POD from " + name, FitPodCurves(hits, options), F0Groups(hits), limits),
                  "image/svg+xml");
}

GapUpload Upload(const json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("text") || !j["text"].is_string())
    throw BadField{where + ": must be {\"name\": \"file name\", \"text\": \"the file's text\"}"};
  for (const auto& [key, value] : j.items())
    if (key != "name" && key != "text") throw BadField{where + ": unknown field '" + key + "'"};
  return {Text(j, "name", where + ".csv"), j["text"].get<std::string>()};
}

void PostGapSvg(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  if (const auto e = EngineerWhenTokens(c, req)) return Send(res, *e);
  const auto parsed = ObjectBody(req, {"simulation", "measured", "quantity", "f_lo_hz", "f_hi_hz",
                                       "sigma_pool", "inertia_kg_m2", "effects", "pairs"});
  if (const ApiError* e = std::get_if<ApiError>(&parsed)) return Send(res, *e);
  const json& body = std::get<json>(parsed);
  GapRunOptions o;
  GapUpload simulation;
  std::vector<GapUpload> measured;
  try {
    if (!body.contains("simulation")) throw BadField{"simulation: required"};
    if (!body.contains("measured")) throw BadField{"measured: required"};
    simulation = Upload(body["simulation"], "simulation");
    const json& units = Array(body, "measured", 1, 8);
    for (std::size_t i = 0; i < units.size(); ++i)
      measured.push_back(Upload(units[i], "measured/" + std::to_string(i)));
    const std::string quantity = Text(body, "quantity", "impedance");
    if (quantity != "impedance" && quantity != "mobility")
      throw BadField{"quantity: must be impedance or mobility (have '" + quantity + "')"};
    o.io.quantity =
        quantity == "mobility" ? analysis::Quantity::kMobility : analysis::Quantity::kImpedanceOhm;
    o.f_lo_hz = Number(body, "f_lo_hz", 0.0, 0.0, 1e6);
    o.f_hi_hz = Number(body, "f_hi_hz", 0.0, 0.0, 1e6);
    const double pool = Number(body, "sigma_pool", 0.0, 0.0, 50.0);
    if (pool != std::floor(pool)) throw BadField{"sigma_pool: must be a whole number of lines"};
    o.sigma_pool = static_cast<int>(pool);
    o.inertia_kg_m2 = Number(body, "inertia_kg_m2", 0.0, 0.0, 1e3);
    if (body.contains("effects"))
      for (const json& e : Array(body, "effects", 1, 32)) {
        const auto kind =
            e.is_string() ? analysis::ParseEffectKind(e.get<std::string>()) : std::nullopt;
        if (!kind) throw BadField{"effects: unknown effect " + Excerpt(e)};
        o.effects.push_back(*kind);
      }
    if (body.contains("pairs")) {
      if (!body["pairs"].is_boolean()) throw BadField{"pairs: must be true or false"};
      o.try_pairs = body["pairs"].get<bool>();
    }
  } catch (const BadField& e) {
    return Send(res, BadRequest(e.message));
  }
  if (c.handlers.current_recipe)
    if (const auto recipe = c.handlers.current_recipe())
      o.fallback_inertia_kg_m2 = recipe->rotor_inertia_kg_m2;
  GapReport report;
  try {
    report = DiagnoseGapUploads(simulation, measured, o);
  } catch (const GapNotUsable& e) {
    return Send(res, ApiError{ApiErrorKind::kUnprocessable, "not_usable", e.what()});
  } catch (const io::FileError& e) {
    return Send(res, ApiError{ApiErrorKind::kBadRequest, "bad_input", e.what()});
  } catch (const io::ConfigError& e) {
    return Send(res, ApiError{ApiErrorKind::kBadRequest, "bad_input", e.what()});
  } catch (const std::invalid_argument& e) {
    return Send(res, ApiError{ApiErrorKind::kBadRequest, "bad_input", e.what()});
  }
  res.status = 200;
  res.set_content(io::RenderChartSvg(GapChart(report)), "image/svg+xml");
}

}  // namespace

void AddFigureRoutes(httplib::Server& s, ApiContext& c) {
  Route(s, c, "POST", R"(/api/pod\.svg)", PostPodSvg, kMaxUploadBytes);
  Route(s, c, "POST", R"(/api/gap\.svg)", PostGapSvg, kMaxUploadBytes);
}

}  // namespace eol::station::http
