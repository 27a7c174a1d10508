// What the HTTP API does with a request's bytes before the station sees them
// (station/daemon/http/request.h): ParseBody gives JSON or a 400/413 ApiError, never an exception;
// a body's "serial" goes through ValidSerial (POST /api/tests); the same bytes as a query
// value go through IntegerParam, NumberParam and TimeParam, which either refuse with
// 400 "bad_<name>" or give a value inside the range (a time in the store's fixed format).
#include <httplib.h>

#include <string>
#include <string_view>

#include "db/serial_number.h"
#include "station/daemon/http/request.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using eol::fuzz::Finding;
using eol::station::http::ApiError;
using eol::station::http::ApiErrorKind;

void CheckRefusal(const std::optional<ApiError>& e, const std::string& name) {
  if (e && (e->kind != ApiErrorKind::kBadRequest || e->code != "bad_" + name))
    Finding(name + ": refused with " + e->code + " instead of 400 bad_" + name);
}

void CheckParams(const std::string& text) {
  httplib::Request req;
  req.params.emplace("limit", text);
  req.params.emplace("k", text);
  req.params.emplace("from", text);
  long long limit = -1;
  const auto e1 = eol::station::http::IntegerParam(req, "limit", 1, 10000, &limit);
  CheckRefusal(e1, "limit");
  if (!e1 && (limit < 1 || limit > 10000)) Finding("IntegerParam gave " + std::to_string(limit));
  double k = -1.0;
  const auto e2 = eol::station::http::NumberParam(req, "k", 0.0, 1e9, &k);
  CheckRefusal(e2, "k");
  if (!e2 && !(k >= 0.0 && k <= 1e9)) Finding("NumberParam gave " + std::to_string(k));
  std::optional<std::string> from;
  const auto e3 = eol::station::http::TimeParam(req, "from", &from);
  CheckRefusal(e3, "from");
  // "YYYY-MM-DDThh:mm:ss.mmmZ" (db/clock.h): fixed width, so string order is time order.
  if (!e3 && (!from || from->size() != 24 || (*from)[10] != 'T' || from->back() != 'Z'))
    Finding("TimeParam gave '" + from.value_or("(nothing)") + "' for '" + text + "'");
}

// db/serial_number.h written out again, independently of its implementation: 1 to 64
// characters from A-Z a-z 0-9 and "-_.:#+", starting with a letter or digit.
bool SerialRule(const std::string& s) {
  auto alnum = [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
  };
  if (s.empty() || s.size() > 64 || !alnum(s[0])) return false;
  for (char c : s)
    if (!alnum(c) && std::string_view("-_.:#+").find(c) == std::string_view::npos) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    httplib::Request req;
    req.body = text;
    const auto parsed = eol::station::http::ParseBody(req);
    if (const ApiError* e = std::get_if<ApiError>(&parsed)) {
      // too_deep: nesting beyond station/daemon/http/request.h's depth limit.
      if (e->code != "bad_json" && e->code != "too_large" && e->code != "too_deep")
        Finding("ParseBody refused with " + e->code);
    } else {
      const nlohmann::json& body = std::get<nlohmann::json>(parsed);
      if (body.is_object() && body.contains("serial") && body["serial"].is_string()) {
        std::string why;
        const std::string serial = body["serial"].get<std::string>();
        const bool valid = eol::db::ValidSerial(serial, &why);
        if (valid != SerialRule(serial))
          Finding("ValidSerial " + std::string(valid ? "accepted" : "refused") + " '" + serial +
                  "' against db/serial_number.h");
        if (!valid && why.empty()) Finding("ValidSerial refused '" + serial + "' without a reason");
      }
    }
    CheckParams(text);
  } catch (...) {
    eol::fuzz::FailOnException("the request readers");
  }
  return 0;
}
