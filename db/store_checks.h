// What Store::Open checks before it uses a file (internal to eol::db; contract in
// db/store.h): the file itself before SQLite opens it, SQLite's quick_check, and verdicts or
// deliveries the store should hold but does not.
#pragma once

#include <sqlite3.h>

#include <string>
#include <vector>

#include "db/last_verdict.h"
#include "db/store.h"

namespace eol::db::internal {

// What a refusal of an empty file tells a person to do.
inline constexpr const char* kInitStoreHint =
    "a store is created only where no file exists; to make this file a new, empty store, "
    "start with --init-store (config \"init_store\": true)";

enum class FileState { kMissing, kEmpty, kHasBytes };

// Reads at most the file's first 100 bytes (SQLite's header) and "<path>.last-verdict";
// creates nothing. Throws StoreRefused for: not a regular file; not an SQLite database; an
// SQLite database of another application (its header's application_id); an empty file
// without options.create_if_empty (kReadOnly: always); a missing file where
// "<path>.last-verdict" names an acknowledged verdict, without options.create_if_empty.
// kReadOnly: a missing file is a StoreError ("no such file").
FileState CheckFile(const std::string& path, Store::Role role, const OpenOptions& options);

// PRAGMA quick_check, interrupted after `budget_ms` (its time grows with the file: about a
// year of a line's tests is tens of GB): throws StoreRefused naming the first problems it
// reports; returns "" when it checked the whole file, otherwise what it left unchecked.
std::string QuickCheck(sqlite3* db, const std::string& path, int budget_ms);

// "" when the store holds test `acked.test_id` with outcome `acked.outcome`; otherwise what is
// missing ("the store ends at test 41, but test 44 (PASS, serial M-7) was acknowledged ...").
std::string FindLostVerdict(sqlite3* db, const std::string& path, const LastVerdict& acked);

// One line per publisher whose cursor is past the newest outbox row (it delivered records
// that are not in the store any more).
std::vector<std::string> FindLostDeliveries(sqlite3* db, const std::string& path);

}  // namespace eol::db::internal
