// `eol query --db FILE --serial SN [--json]`: the traceable history of one serial number.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "db/store.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/serial_number.h"

namespace eol::station::cli {
namespace {

struct QueryArgs {
  std::string db;
  std::string serial;
  bool json = false;
  bool curves = false;
};

int RunQuery(const QueryArgs& a) {
  std::string why;
  if (!ValidSerial(a.serial, &why)) throw std::runtime_error("--serial: " + why);
  auto store = db::Store::Open(a.db, db::Store::Role::kReader);
  const std::vector<db::TestRecord> tests = store->TestsOfSerial(a.serial, a.curves);
  if (a.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& t : tests) list.push_back(t);
    const nlohmann::json out = {
        {"serial", a.serial},
        {"latest", tests.empty() ? nlohmann::json() : nlohmann::json(tests.front())},
        {"tests", list}};
    std::cout << out.dump(2) << std::endl;
    return tests.empty() ? 1 : 0;
  }
  if (tests.empty()) {
    std::cout << a.serial << ": no tests in " << a.db << "\n";
    return 1;
  }
  std::cout << a.serial << ": " << tests.size() << " test(s), latest "
            << analysis::ToString(tests.front().outcome) << "\n";
  for (const auto& t : tests) {
    std::printf("  #%-6lld %s  %-7s recipe %s v%d (%s)%s\n", static_cast<long long>(t.id),
                t.started_at.c_str(), analysis::ToString(t.outcome), t.recipe_id.c_str(),
                t.recipe_version, t.recipe_hash.substr(0, 12).c_str(),
                t.retest_of ? (" retest of #" + std::to_string(*t.retest_of)).c_str() : "");
    for (const auto& m : t.measurements) {
      if (!std::isfinite(m.value)) continue;
      std::printf("          %-18s %12.6g %-4s [%s] %s\n", m.name.c_str(), m.value, m.unit.c_str(),
                  analysis::ToString(m.outcome), m.marginal ? "marginal" : "");
    }
    for (const auto& r : t.reasons)
      std::printf("          reason (%s): %s\n", analysis::ToString(r.code), r.text.c_str());
  }
  return 0;
}

}  // namespace

void AddQueryCommand(CLI::App& app) {
  auto args = std::make_shared<QueryArgs>();
  CLI::App* cmd = app.add_subcommand(
      "query",
      "Show every test of a serial number, newest first, with measurements, limits, verdict,\n"
      "reasons and recipe hash. Exit code 1 when the serial has no tests.");
  cmd->add_option("--db", args->db, "SQLite file of the station")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--serial", args->serial, "Serial number")->required();
  cmd->add_flag("--json", args->json, "One JSON object: {serial, latest, tests}");
  cmd->add_flag("--curves", args->curves, "With --json: include the raw curves");
  cmd->callback([args] { RunGuarded("query", [&] { return RunQuery(*args); }); });
}

}  // namespace eol::station::cli
