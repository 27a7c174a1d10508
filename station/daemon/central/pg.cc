#include "station/daemon/central/pg.h"

#include <libpq-fe.h>

namespace eol::station::central {
namespace {

// libpq's messages end with a newline; the log lines are one line each.
std::string Trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

PgResult::PgResult(pg_result* r) : r_(r) {}
PgResult::~PgResult() { PQclear(r_); }
PgResult::PgResult(PgResult&& other) noexcept : r_(other.r_) { other.r_ = nullptr; }
int PgResult::rows() const { return PQntuples(r_); }
bool PgResult::IsNull(int row, int col) const { return PQgetisnull(r_, row, col) == 1; }
std::string PgResult::Text(int row, int col) const {
  return std::string(PQgetvalue(r_, row, col), static_cast<std::size_t>(PQgetlength(r_, row, col)));
}
long long PgResult::affected() const {
  const char* n = PQcmdTuples(r_);
  return n == nullptr || *n == '\0' ? 0 : std::stoll(n);
}

PgConnection::PgConnection(pg_conn* c, std::string where) : c_(c), where_(std::move(where)) {}
PgConnection::~PgConnection() { PQfinish(c_); }

std::unique_ptr<PgConnection> PgConnection::Connect(const std::string& url, int connect_timeout_s,
                                                    const std::string& who) {
  const std::string timeout = std::to_string(connect_timeout_s);
  const std::string app = "eol-" + who;
  // dbname first: expand_dbname reads the URL from it, and the keywords after it override.
  const char* keys[] = {"dbname",
                        "connect_timeout",
                        "application_name",
                        "keepalives_idle",
                        "keepalives_interval",
                        "keepalives_count",
                        "tcp_user_timeout",
                        nullptr};
  const char* values[] = {url.c_str(), timeout.c_str(), app.c_str(), "10", "5",
                          "2",         "15000",         nullptr};
  pg_conn* c = PQconnectdbParams(keys, values, /*expand_dbname=*/1);
  const std::string where = RedactUrl(url);
  if (c == nullptr) throw PgError("postgres " + where + ": connect: libpq is out of memory");
  if (PQstatus(c) != CONNECTION_OK) {
    const std::string why = Trim(PQerrorMessage(c));
    PQfinish(c);
    throw PgError("postgres " + where + ": connect: " + why);
  }
  // The server's NOTICEs ("relation ... already exists, skipping" at every schema check)
  // would go to stderr one by one; errors reach the caller as PgError.
  PQsetNoticeProcessor(
      c, [](void*, const char*) {}, nullptr);
  return std::unique_ptr<PgConnection>(new PgConnection(c, where));
}

namespace {

// Throws unless `r` (owned by the caller's PgResult) reports success.
void Check(pg_conn* c, pg_result* r, const std::string& where, const std::string& op) {
  const ExecStatusType status = r == nullptr ? PGRES_FATAL_ERROR : PQresultStatus(r);
  if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return;
  std::string why = r != nullptr ? Trim(PQresultErrorMessage(r)) : "";
  if (why.empty()) why = Trim(PQerrorMessage(c));
  if (why.empty()) why = PQresStatus(status);
  throw PgError("postgres " + where + ": " + op + ": " + why);
}

}  // namespace

PgResult PgConnection::Exec(const std::string& sql, const PgParams& params, const std::string& op) {
  std::vector<const char*> values;
  values.reserve(params.size());
  for (const auto& p : params) values.push_back(p ? p->c_str() : nullptr);
  PgResult r(PQexecParams(c_, sql.c_str(), static_cast<int>(values.size()), nullptr, values.data(),
                          nullptr, nullptr, /*resultFormat=*/0));
  Check(c_, r.get(), where_, op);
  return r;
}

void PgConnection::Run(const std::string& sql, const std::string& op) {
  PgResult r(PQexec(c_, sql.c_str()));
  Check(c_, r.get(), where_, op);
}

bool PgConnection::ok() const { return PQstatus(c_) == CONNECTION_OK; }

}  // namespace eol::station::central
