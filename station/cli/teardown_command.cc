// `eol teardown --db DB --serial S [--found defective|not-defective --by NAME [--note TEXT]]
// [--json]`: records what teardown of a unit found (db/store.h TeardownEntry; append-only,
// a correction is a new finding) or, without --found, lists every finding of the serial
// with the verdict it judged (station/reports/teardown_review.h).
// Exit: 0 recorded / listed, 1 the serial has no finding (listing), 2 usage, an unknown
// serial or a store that cannot be written.
#include <iostream>
#include <nlohmann/json.hpp>

#include "db/clock.h"
#include "db/serial_number.h"
#include "db/store.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/reports/teardown_review.h"

namespace eol::station::cli {
namespace {

struct TeardownArgs {
  std::string db;
  std::string serial;
  std::string found;
  std::string by;
  std::string note;
  bool json = false;
};

std::string VerdictOf(db::Store& store, const db::TeardownEntry& e) {
  if (!e.test_id) return "-";
  const auto t = store.Test(*e.test_id, false);
  return t ? std::string(analysis::ToString(t->outcome)) : "-";
}

void PrintEntry(const db::TeardownEntry& e, const std::string& verdict) {
  std::cout << "  #" << e.id << " " << e.at << "  " << db::ToString(e.found) << " (judged test #"
            << (e.test_id ? std::to_string(*e.test_id) : "-") << ", " << verdict << ") by " << e.by
            << (e.corrects ? ", corrects #" + std::to_string(*e.corrects) : "")
            << (e.note.empty() ? "" : ": " + e.note) << "\n";
}

int Record(const TeardownArgs& a) {
  const auto found = db::ParseTeardownFinding(a.found);
  if (!found) throw std::runtime_error("--found: '" + a.found + "': defective or not-defective");
  if (a.by.find_first_not_of(" \t") == std::string::npos)
    throw std::runtime_error("--by: the engineer's name is required to record a finding");
  // kReader: the station may be running (it holds the writer's lock); this only appends.
  auto store = db::Store::Open(a.db, db::Store::Role::kReader);
  db::TeardownEntry e;
  e.serial = a.serial;
  e.found = *found;
  e.by = a.by;
  e.note = a.note;
  e.at = db::UtcNowIso8601();
  const db::TeardownEntry stored = store->AppendTeardown(e);
  const std::string verdict = VerdictOf(*store, stored);
  if (a.json) {
    nlohmann::json j = TeardownJson(stored);
    j["verdict"] = verdict;
    std::cout << j.dump() << std::endl;
    return 0;
  }
  std::cout << a.serial << ": recorded teardown finding\n";
  PrintEntry(stored, verdict);
  if (stored.found == db::TeardownFinding::kNotDefective && verdict == "FAIL")
    std::cout << "  false reject: the station failed a unit teardown found not defective\n";
  if (stored.found == db::TeardownFinding::kDefective && verdict == "PASS")
    std::cout << "  escape: the station passed a unit teardown found defective\n";
  return 0;
}

int List(const TeardownArgs& a) {
  auto store = db::Store::Open(a.db, db::Store::Role::kReadOnly);
  const std::vector<db::TeardownEntry> history = store->TeardownsOfSerial(a.serial);
  if (a.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& e : history) {
      nlohmann::json j = TeardownJson(e);
      j["verdict"] = VerdictOf(*store, e);
      list.push_back(std::move(j));
    }
    std::cout << nlohmann::json{{"serial", a.serial}, {"teardowns", list}}.dump() << std::endl;
    return history.empty() ? 1 : 0;
  }
  if (history.empty()) {
    std::cout << a.serial << ": no teardown finding in " << a.db << "\n";
    return 1;
  }
  std::cout << a.serial << ": " << history.size() << " teardown finding(s), current "
            << db::ToString(history.back().found) << "\n";
  for (const auto& e : history) PrintEntry(e, VerdictOf(*store, e));
  return 0;
}

int RunTeardown(const TeardownArgs& a) {
  std::string why;
  if (!db::ValidSerial(a.serial, &why)) throw std::runtime_error("--serial: " + why);
  return a.found.empty() ? List(a) : Record(a);
}

}  // namespace

void AddTeardownCommand(CLI::App& app) {
  auto args = std::make_shared<TeardownArgs>();
  CLI::App* cmd = app.add_subcommand(
      "teardown",
      "Record what teardown of a unit found (--found, --by), or list every finding of a\n"
      "serial (without --found). Findings are append-only: a correction is a new finding,\n"
      "the history stays. A finding judges the serial's newest test: defective after FAIL is\n"
      "a hit, after PASS an escape; not-defective after FAIL a false reject.\n"
      "Read by `eol teach --known-bad-from-db` and `eol pod --from-db`.\n"
      "Exit: 0 recorded or listed, 1 the serial has no finding, 2 usage error or a serial\n"
      "the store never tested.");
  cmd->add_option("--db", args->db, "SQLite file of the station")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--serial", args->serial, "Serial number")->required();
  cmd->add_option("--found", args->found, "What teardown found")
      ->check(CLI::IsMember({"defective", "not-defective"}));
  cmd->add_option("--by", args->by, "The engineer who records it (with --found)")->needs("--found");
  cmd->add_option("--note", args->note, "What was found, in words (with --found)")
      ->needs("--found");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("teardown", [&] { return RunTeardown(*args); }); });
}

}  // namespace eol::station::cli
