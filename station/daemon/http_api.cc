#include "station/daemon/http_api.h"

#include <spdlog/spdlog.h>

#include "db/store.h"
#include "station/daemon/http/context.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http/routes.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include "station/daemon/http/gate.h"
#include "station/daemon/http/server.h"

namespace eol::station {

HttpApi::HttpApi(StatusBoard& board, HttpOptions options, HttpHandlers handlers)
    : context_(std::make_unique<http::ApiContext>(board, std::move(options), std::move(handlers))) {
}

HttpApi::~HttpApi() { Stop(); }

void HttpApi::Start() {
  const HttpOptions& o = context_->options;
  context_->db = db::Store::Open(o.db_path, db::Store::Role::kReader);
  server_ = std::make_unique<http::ApiServer>(o.limits);
  server_->set_payload_max_length(http::kMaxUploadBytes);  // each route enforces its own
  http::InstallGate(*server_, *context_);
  http::AddBoardRoutes(*server_, *context_);
  http::AddRecipeRoutes(*server_, *context_);
  http::AddTestRoutes(*server_, *context_);
  http::AddQcRoutes(*server_, *context_);
  http::AddFigureRoutes(*server_, *context_);
  http::AddTeardownRoutes(*server_, *context_);
  server_->set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unknown";
        try {
          std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
        }
        spdlog::error("http: {} {}: {}", req.method, req.path, what);
        http::Send(res, http::ApiError{http::ApiErrorKind::kInternal, "internal", what});
      });
  std::string why;
  port_ = server_->Bind(o.listen, o.port, &why);
  if (port_ <= 0)
    throw std::runtime_error("http: cannot listen on " + o.listen + ":" + std::to_string(o.port) +
                             ": " + why);
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  spdlog::info("http: serving on http://{}:{}/", o.listen, port_);
}

void HttpApi::Stop() {
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace eol::station
