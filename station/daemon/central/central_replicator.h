// Replicates the station's stored records into the plant's central PostgreSQL record
// (station/daemon/central/central_schema.h), from the store's outbox with its own cursor "central"
// (db/store.h), beside the MQTT publisher's "mqtt" cursor: either can be far behind the
// other, and neither ever slows a test.
//
// Exactly once: a batch of up to `batch` outbox rows is inserted in ONE transaction with
// INSERT ... ON CONFLICT (station_id, test_id) DO NOTHING; only after its COMMIT succeeded
// does the cursor move past the batch (a durable SQLite write). A station stopped or killed
// between the two sends the batch again at its next start, and the rows already there are
// left alone; a COMMIT that failed (server stopped, network gone) moved nothing and is sent
// again. So after any sequence of outages and restarts each record is in `tests` once.
//
// The station never waits on it: its own thread and its own SQLite connection. While the
// server cannot be reached it tries again after retry_min_s, doubling to retry_max_s, and
// logs the first failure of an outage (with the error) and the recovery (with the backlog),
// not every attempt. status() gives the backlog (outbox rows after its cursor) for the
// status board and /metrics.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace eol::station::central {

// The "central" block of the station config (station/daemon/config.cc checks the ranges).
struct CentralConfig {
  std::string postgres;       // libpq URI "postgresql://user@host:5432/db" (password allowed)
  int batch = 200;            // outbox rows per transaction, 1..10000
  double retry_min_s = 0.5;   // first pause after a failure
  double retry_max_s = 30.0;  // the pause doubles up to this
  int connect_timeout_s = 5;  // libpq connect_timeout
  double idle_poll_s = 0.05;  // how often an idle replicator looks at the outbox
};

// For station/README.md, /metrics and tests.
struct CentralStatus {
  bool connected = false;
  std::int64_t backlog = -1;        // outbox rows not yet in the central record (-1: unknown)
  std::uint64_t inserted = 0;       // rows this process inserted
  std::uint64_t already_there = 0;  // rows found there already (sent again after a restart)
  std::uint64_t failures = 0;       // failed attempts (connect or transaction)
  std::string last_error;           // empty once it works again
};

class CentralReplicator {
 public:
  // `db_path`: the station's store (the replicator opens its own connection);
  // `who`: the station id, in application_name and the logs.
  CentralReplicator(CentralConfig config, std::string db_path, std::string who);
  ~CentralReplicator();  // Stop()
  CentralReplicator(const CentralReplicator&) = delete;
  CentralReplicator& operator=(const CentralReplicator&) = delete;

  void Start();
  // Finishes the transaction in flight (committed or rolled back, never half) and joins.
  // Idempotent.
  void Stop();

  CentralStatus status() const;

 private:
  void Run();

  const CentralConfig config_;
  const std::string db_path_;
  const std::string who_;
  std::thread thread_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  mutable std::mutex status_mu_;
  CentralStatus status_;
};

}  // namespace eol::station::central
