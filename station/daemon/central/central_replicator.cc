#include "station/daemon/central/central_replicator.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <vector>

#include "db/store.h"
#include "station/daemon/central/central_record.h"
#include "station/daemon/central/pg.h"

namespace eol::station::central {
namespace {

constexpr const char* kConsumer = "central";

}  // namespace

CentralReplicator::CentralReplicator(CentralConfig config, std::string db_path, std::string who)
    : config_(std::move(config)), db_path_(std::move(db_path)), who_(std::move(who)) {}

CentralReplicator::~CentralReplicator() { Stop(); }

void CentralReplicator::Start() {
  if (thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = false;
  }
  thread_ = std::thread([this] { Run(); });
}

void CentralReplicator::Stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

CentralStatus CentralReplicator::status() const {
  std::lock_guard<std::mutex> lock(status_mu_);
  return status_;
}

void CentralReplicator::Run() {
  std::unique_ptr<db::Store> store;
  try {
    store = db::Store::Open(db_path_, db::Store::Role::kReader);
  } catch (const std::exception& e) {
    spdlog::error("central: cannot read the outbox: {}; nothing will be replicated", e.what());
    std::lock_guard<std::mutex> lock(status_mu_);
    status_.last_error = e.what();
    return;
  }
  const std::string where = RedactUrl(config_.postgres);
  std::unique_ptr<PgConnection> pg;
  double pause_s = config_.retry_min_s;
  bool outage = false;  // the first failure of an outage is logged, the recovery too
  const auto wait = [this](double s) {
    std::unique_lock<std::mutex> lock(mu_);
    return cv_.wait_for(lock, std::chrono::duration<double>(s), [this] { return stop_; });
  };
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (stop_) break;
    }
    std::int64_t backlog = -1;
    try {
      backlog = store->OutboxPending(kConsumer);
    } catch (const std::exception& e) {
      spdlog::error("central: outbox: {}", e.what());
    }
    {
      std::lock_guard<std::mutex> lock(status_mu_);
      status_.backlog = backlog;
    }
    if (backlog <= 0) {
      if (wait(config_.idle_poll_s)) break;
      continue;
    }
    bool in_transaction = false;
    try {
      if (!pg || !pg->ok()) {
        pg.reset();
        pg = PgConnection::Connect(config_.postgres, config_.connect_timeout_s, who_);
        EnsureCentralSchema(*pg);
      }
      const std::vector<db::OutboxEntry> rows = store->OutboxAfterCursor(kConsumer, config_.batch);
      std::uint64_t inserted = 0, there = 0;
      pg->Run("BEGIN", "begin a batch");
      in_transaction = true;
      for (const db::OutboxEntry& row : rows) {
        // A record deleted since (its outbox row goes with it) cannot be here; an ABORTED
        // test recovered at start has a record of its columns only.
        const std::optional<db::TestRecord> record = store->Test(row.test_id, true);
        if (!record) continue;
        (InsertCentral(*pg, *record, row.created_at) ? inserted : there) += 1;
      }
      pg->Run("COMMIT", "commit a batch of " + std::to_string(rows.size()));
      in_transaction = false;
      if (!rows.empty()) store->AdvanceOutboxCursor(kConsumer, rows.back().id);
      if (outage)
        spdlog::info("central {}: replicating again ({} records waiting)", where, backlog);
      outage = false;
      pause_s = config_.retry_min_s;
      std::lock_guard<std::mutex> lock(status_mu_);
      status_.connected = true;
      status_.inserted += inserted;
      status_.already_there += there;
      status_.backlog = backlog - static_cast<std::int64_t>(rows.size());
      status_.last_error.clear();
    } catch (const std::exception& e) {
      // A failed transaction moved no cursor; the whole batch goes again.
      if (in_transaction && pg && pg->ok()) {
        try {
          pg->Run("ROLLBACK", "roll back a failed batch");
        } catch (const std::exception&) {
          pg.reset();
        }
      } else {
        pg.reset();
      }
      if (!outage)
        spdlog::warn(
            "central: {}; {} records wait in the outbox, next attempt in {} s (then "
            "backing off to {} s)",
            e.what(), backlog, pause_s, config_.retry_max_s);
      outage = true;
      {
        std::lock_guard<std::mutex> lock(status_mu_);
        status_.connected = pg != nullptr;
        ++status_.failures;
        status_.last_error = e.what();
      }
      if (wait(pause_s)) break;
      pause_s = std::min(pause_s * 2, config_.retry_max_s);
    }
  }
}

}  // namespace eol::station::central
