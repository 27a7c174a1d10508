// Test support: what the plant's central record and a station's SQLite hold, for checking
// exactly-once replication (station/daemon/central/central_replicator.h).
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "db/store.h"
#include "station/daemon/central/pg.h"

namespace eol::testing {

// (station_id, test_id) -> how many rows the central `tests` table holds. Throws PgError
// when the server cannot be read (or no replicator has created the table yet).
inline std::map<std::pair<std::string, std::int64_t>, int> CentralCounts(const std::string& url) {
  auto pg = station::central::PgConnection::Connect(url, 5, "test");
  const station::central::PgResult r = pg->Exec(
      "SELECT station_id, test_id, count(*) FROM tests GROUP BY station_id, test_id", {}, "count");
  std::map<std::pair<std::string, std::int64_t>, int> out;
  for (int i = 0; i < r.rows(); ++i)
    out[{r.Text(i, 0), std::stoll(r.Text(i, 1))}] = std::stoi(r.Text(i, 2));
  return out;
}

// Every test id the station's SQLite holds (up to 10000).
inline std::set<std::int64_t> StationIds(const std::string& db_path) {
  auto store = db::Store::Open(db_path, db::Store::Role::kReader);
  db::TestQuery q;
  q.limit = 10000;
  std::set<std::int64_t> ids;
  for (const db::TestRecord& r : store->Tests(q)) ids.insert(r.id);
  return ids;
}

}  // namespace eol::testing
