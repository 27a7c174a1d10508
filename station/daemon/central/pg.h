// A small RAII face of libpq for the plant's central record (station/daemon/central/): one
// connection, parameterised statements in text format, results freed by their owner.
//
// Contract: every call either does what it says or throws PgError whose message names the
// operation, the server (the URL without its password) and libpq's or the server's message.
// Nothing here retries: the caller decides (the replicator backs off and says so in the log).
// Not thread-safe: one connection per thread, as libpq requires.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "station/daemon/plant_urls.h"  // RedactUrl

struct pg_conn;    // libpq's PGconn
struct pg_result;  // libpq's PGresult

namespace eol::station::central {

class PgError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The rows of one statement's result. Values are libpq's text format.
class PgResult {
 public:
  explicit PgResult(pg_result* r);
  ~PgResult();
  PgResult(PgResult&& other) noexcept;
  PgResult& operator=(PgResult&&) = delete;
  PgResult(const PgResult&) = delete;
  PgResult& operator=(const PgResult&) = delete;

  int rows() const;
  bool IsNull(int row, int col) const;
  std::string Text(int row, int col) const;
  // The count of an INSERT/UPDATE/DELETE (PQcmdTuples), 0 for other statements.
  long long affected() const;
  pg_result* get() const { return r_; }

 private:
  pg_result* r_;
};

// Statement parameters: nullopt is SQL NULL.
using PgParams = std::vector<std::optional<std::string>>;

class PgConnection {
 public:
  // Connects to `url` (a libpq URI or conninfo string), waiting at most `connect_timeout_s`;
  // TCP keepalives and a user timeout make a vanished server an error within ~15 s instead
  // of a hang. application_name is "eol-<who>".
  static std::unique_ptr<PgConnection> Connect(const std::string& url, int connect_timeout_s,
                                               const std::string& who);
  ~PgConnection();
  PgConnection(const PgConnection&) = delete;
  PgConnection& operator=(const PgConnection&) = delete;

  // Runs one statement with $1.. parameters; `op` names it in errors. Throws PgError unless
  // the server reports success.
  PgResult Exec(const std::string& sql, const PgParams& params, const std::string& op);
  // Runs SQL without parameters (may hold several statements).
  void Run(const std::string& sql, const std::string& op);
  // Whether libpq still believes the connection is usable (CONNECTION_OK).
  bool ok() const;
  const std::string& where() const { return where_; }

 private:
  PgConnection(pg_conn* c, std::string where);
  pg_conn* c_;
  std::string where_;  // the redacted URL
};

}  // namespace eol::station::central
