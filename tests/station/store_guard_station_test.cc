// Issue 34 through the station and the binary: a damaged, emptied or foreign store stops
// `eol station` (exit 65, the cause on stderr), `eol demo` and `eol query` with the file and
// the problem named; verdicts the store lost are named at start; a store write that fails in
// a test ends it ERROR, shows the station not ready with the cause, and leaves no RUNNING row.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "db/last_verdict.h"
#include "db/store.h"
#include "station/daemon/station.h"
#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"

namespace eol::station {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using eol::testing::RunEol;
using eol::testing::TempDir;

nlohmann::json Config(const std::string& db) {
  return {{"station_id", "guard-1"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", db},
          {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
          {"fixture", {{"driver", "sim"}}},
          {"daq", {{"driver", "sim"}}}};
}

std::set<std::string> Files(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

void Sql(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* err = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK)
      << sql << ": " << (err != nullptr ? err : "");
  sqlite3_free(err);
  sqlite3_close(db);
}

TEST(StoreGuardStation, AnEmptiedStoreStopsTheDaemonWithExit65AndTheCause) {
  TempDir dir;
  const std::string db = dir / "eol.sqlite";
  std::ofstream(db).flush();  // 0 bytes: a store truncated by accident
  std::ofstream(dir / "station.json") << Config(db).dump();
  const auto run = RunEol({"station", "--config", dir / "station.json"}, true, 60s);
  EXPECT_EQ(run.code, 65) << run.out;
  EXPECT_NE(run.out.find("store refused: store '" + db + "': open: the file is empty (0 bytes)"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("--init-store"), std::string::npos) << run.out;
  EXPECT_EQ(fs::file_size(db), 0u);
}

TEST(StoreGuardStation, DemoOnAFileThatIsNoStoreLeavesNoSideFile) {
  TempDir dir;
  const std::string passwd = dir / "passwd";
  std::ofstream(passwd) << "root:x:0:0:root:/root:/bin/bash\n";
  const auto run = RunEol({"demo", "--units", "1", "--port", "0", "--db", passwd}, true, 60s);
  EXPECT_NE(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("store '" + passwd + "': open: not a database"), std::string::npos)
      << run.out;
  EXPECT_EQ(Files(dir.path()), std::set<std::string>{"passwd"});
}

TEST(StoreGuardStation, QueryOnADamagedStoreNamesThePage) {
  TempDir dir;
  const std::string db = dir / "eol.sqlite";
  {
    auto store = db::Store::Open(db);
    for (int i = 0; i < 20; ++i) {
      db::TestRecord r;
      r.serial = "Q-" + std::to_string(i);
      r.station_id = "s";
      r.recipe_id = "r";
      r.recipe_hash = std::string(64, 'a');
      r.software_version = "t";
      r.started_at = r.finished_at = "2026-11-28T10:00:00.000Z";
      r.outcome = analysis::Outcome::kPass;
      store->Insert(r);
    }
  }
  std::string page;
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(raw, "SELECT rootpage FROM sqlite_schema WHERE name = 'tests'", -1, &s,
                       nullptr);
    ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
    page = reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
    sqlite3_finalize(s);
    sqlite3_close(raw);
  }
  {
    std::fstream f(db, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp((std::stoi(page) - 1) * 4096);
    f.write(std::string(4096, '\0').data(), 4096);
  }
  const auto run = RunEol({"query", "--db", db, "--serial", "Q-1"}, true, 60s);
  EXPECT_NE(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("store '" + db + "': open (PRAGMA quick_check): the store is damaged"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("Page " + page + ": "), std::string::npos) << run.out;
}

TEST(StoreGuardStation, LostVerdictsAreNamedAtStartAndTheirIdsNotReused) {
  TempDir dir;
  const std::string db = dir / "eol.sqlite";
  {
    Station s(ParseStationConfig(Config(db), "test", ""));
    ASSERT_EQ(s.RunTest("L-1").id, 1);
  }
  // The store lost tests 2 to 9 (an older copy restored): the last-verdict file says 9.
  {
    std::FILE* f = std::fopen(db::LastVerdictPath(db).c_str(), "r+");
    ASSERT_NE(f, nullptr);
    EXPECT_EQ(db::WriteLastVerdict(fileno(f), {9, "PASS", "2026-11-28T11:00:00.000Z", "L-9"}), "");
    std::fclose(f);
  }
  Station s(ParseStationConfig(Config(db), "test", ""));
  const nlohmann::json board = s.board().Snapshot();
  EXPECT_FALSE(board.value("ready", true));
  EXPECT_EQ(board.value("message", ""),
            "store lost acknowledged verdicts: the store ends at test 1, but test 9 (PASS, "
            "serial L-9) was acknowledged at 2026-11-28T11:00:00.000Z: the records of tests 2 "
            "to 9 are lost (a deleted or damaged WAL, or an older copy of the file); new tests "
            "are numbered from 10");
  EXPECT_NE(board.value("not_ready_reason", "").find("test 9 (PASS, serial L-9)"),
            std::string::npos);
  EXPECT_EQ(s.RunTest("L-10").id, 10);
}

TEST(StoreGuardStation, AFailedStoreWriteEndsTheTestErrorAndTheStationNotReady) {
  TempDir dir;
  const std::string db = dir / "eol.sqlite";
  Station s(ParseStationConfig(Config(db), "test", ""));
  ASSERT_EQ(s.RunTest("W-1").outcome, analysis::Outcome::kPass);
  // The verdict's write fails as on a full disk; the ERROR that replaces it still fits.
  Sql(db,
      "CREATE TRIGGER no_space BEFORE UPDATE OF outcome ON tests "
      "WHEN NEW.outcome IN ('PASS', 'FAIL') "
      "BEGIN SELECT RAISE(ABORT, 'database or disk is full (simulated)'); END");
  const db::TestRecord r = s.RunTest("W-2");
  EXPECT_EQ(r.outcome, analysis::Outcome::kError);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_NE(r.reasons[0].text.find("record not stored"), std::string::npos) << r.reasons[0].text;
  nlohmann::json board = s.board().Snapshot();
  EXPECT_FALSE(board.value("ready", true));
  EXPECT_NE(board.value("not_ready_reason", "")
                .find("store write failed: store '" + db + "': finish test 2"),
            std::string::npos)
      << board.dump();
  EXPECT_NE(board.value("not_ready_reason", "").find("database or disk is full (simulated)"),
            std::string::npos);
  EXPECT_EQ(s.store().CountRunning(), 0);
  const auto stored = s.store().Test(r.id);
  ASSERT_TRUE(stored.has_value());
  EXPECT_EQ(stored->outcome, analysis::Outcome::kError);
  EXPECT_NE(stored->reasons.at(0).text.find("store write failed: "), std::string::npos);
  // Space again: the next test passes and the station is ready.
  Sql(db, "DROP TRIGGER no_space");
  EXPECT_EQ(s.RunTest("W-3").outcome, analysis::Outcome::kPass);
  board = s.board().Snapshot();
  EXPECT_TRUE(board.value("ready", false)) << board.dump();
  EXPECT_EQ(board.value("message", "x"), "");
}

}  // namespace
}  // namespace eol::station
