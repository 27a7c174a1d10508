// The store's thin layer over SQLite's C API (internal to eol::db: db/store*.cc only).
#pragma once

#include <sqlite3.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "db/store.h"

namespace eol::db::internal {

// How long a writer waits for another connection's lock before the operation fails.
constexpr int kBusyTimeoutMs = 5000;

inline std::string Message(const std::string& path, const std::string& op,
                           const std::string& detail) {
  return "store '" + path + "': " + op + ": " + detail;
}

// The connection's last error; for a lock, also how long SQLite was allowed to wait for it.
[[noreturn]] inline void ThrowSqlite(sqlite3* db, const std::string& path, const std::string& op) {
  std::string detail = sqlite3_errmsg(db);
  const int rc = sqlite3_extended_errcode(db);
  detail += " (sqlite code " + std::to_string(rc) + ")";
  if ((rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED)
    detail += "; busy timeout " + std::to_string(kBusyTimeoutMs) + " ms";
  // A damaged file stays damaged: no retry or restart helps.
  if ((rc & 0xff) == SQLITE_CORRUPT || (rc & 0xff) == SQLITE_NOTADB)
    throw StoreRefused(Message(path, op, detail + "; the file is damaged or not a store"));
  throw StoreError(Message(path, op, detail));
}

// Runs SQL without parameters (PRAGMAs with constant values, transaction control, DDL).
inline void Exec(sqlite3* db, const std::string& path, const char* sql, const std::string& op) {
  if (sqlite3_exec(db, sql, nullptr, nullptr, nullptr) != SQLITE_OK) ThrowSqlite(db, path, op);
}

// One prepared statement, finalised when it goes out of scope. Errors name `op`.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& path, std::string_view sql, std::string op)
      : db_(db), path_(path), op_(std::move(op)) {
    if (sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr) !=
        SQLITE_OK)
      ThrowSqlite(db_, path_, op_);
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void BindNull(int i) { Check(sqlite3_bind_null(stmt_, i)); }
  void BindInt(int i, std::int64_t v) { Check(sqlite3_bind_int64(stmt_, i, v)); }
  // Not finite -> NULL, as in the record's JSON.
  void BindReal(int i, double v) {
    if (std::isfinite(v))
      Check(sqlite3_bind_double(stmt_, i, v));
    else
      BindNull(i);
  }
  void BindReal(int i, const std::optional<double>& v) {
    if (v)
      BindReal(i, *v);
    else
      BindNull(i);
  }
  void BindText(int i, std::string_view v) {
    // A null pointer would bind NULL; an empty string must stay an empty string.
    Check(sqlite3_bind_text64(stmt_, i, v.data() != nullptr ? v.data() : "", v.size(),
                              SQLITE_TRANSIENT, SQLITE_UTF8));
  }
  void BindBlob(int i, const void* data, std::size_t size) {
    Check(sqlite3_bind_blob64(stmt_, i, data, size, SQLITE_TRANSIENT));
  }

  // True when a row is ready, false when the statement is done.
  bool Step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    ThrowSqlite(db_, path_, op_);
  }
  void Run() {
    while (Step()) {
    }
  }
  void Reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }

  bool IsNull(int c) const { return sqlite3_column_type(stmt_, c) == SQLITE_NULL; }
  std::int64_t Int(int c) const { return sqlite3_column_int64(stmt_, c); }
  std::optional<std::int64_t> OptInt(int c) const {
    return IsNull(c) ? std::nullopt : std::optional<std::int64_t>(Int(c));
  }
  std::optional<double> OptReal(int c) const {
    return IsNull(c) ? std::nullopt : std::optional<double>(sqlite3_column_double(stmt_, c));
  }
  // NULL -> "".
  std::string Text(int c) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, c));
    const int n = sqlite3_column_bytes(stmt_, c);
    return p != nullptr ? std::string(p, static_cast<std::size_t>(n)) : std::string();
  }
  std::string_view Blob(int c) const {
    const auto* p = static_cast<const char*>(sqlite3_column_blob(stmt_, c));
    const int n = sqlite3_column_bytes(stmt_, c);
    return p != nullptr ? std::string_view(p, static_cast<std::size_t>(n)) : std::string_view();
  }

 private:
  void Check(int rc) {
    if (rc != SQLITE_OK) ThrowSqlite(db_, path_, op_);
  }

  sqlite3* db_;
  const std::string& path_;
  std::string op_;
  sqlite3_stmt* stmt_ = nullptr;
};

// BEGIN IMMEDIATE (takes the write lock now, so the transaction cannot fail half-way for a
// lock); rolled back unless committed.
class Transaction {
 public:
  Transaction(sqlite3* db, const std::string& path, std::string op)
      : db_(db), path_(path), op_(std::move(op)) {
    Exec(db_, path_, "BEGIN IMMEDIATE", op_ + ": begin transaction");
  }
  ~Transaction() {
    if (!committed_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;

  // Durable when it returns (WAL with synchronous=FULL syncs the log on commit).
  void Commit() {
    Exec(db_, path_, "COMMIT", op_ + ": commit");
    committed_ = true;
  }

 private:
  sqlite3* db_;
  const std::string& path_;
  std::string op_;
  bool committed_ = false;
};

inline std::int64_t PragmaInt(sqlite3* db, const std::string& path, const char* sql,
                              const std::string& op) {
  Statement s(db, path, sql, op);
  if (!s.Step()) throw StoreError(Message(path, op, "no result"));
  return s.Int(0);
}

}  // namespace eol::db::internal
