// `eol report --db DB --serial S --out S.pdf [--test-id N] [--recipe FILE] [--json]`: the printable
// report of one unit's test (station/reports/unit_report.h), its newest finished test or test N.
// Exit: 0 written, 1 the serial has no such test, 2 usage or a file that cannot be written.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "db/clock.h"
#include "db/serial_number.h"
#include "db/store.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/recipe.h"
#include "station/daemon/version.h"
#include "station/reports/unit_report.h"

namespace eol::station::cli {
namespace {

struct ReportArgs {
  std::string db;
  std::string serial;
  std::string out;
  long long test_id = 0;
  std::string recipe;
  bool json = false;
};

int RunReport(const ReportArgs& a) {
  std::string why;
  if (!db::ValidSerial(a.serial, &why)) throw std::runtime_error("--serial: " + why);
  std::string hash;
  std::vector<analysis::CurveMask> masks;
  if (!a.recipe.empty()) {
    const Recipe recipe = LoadRecipe(a.recipe);
    hash = recipe.hash;
    masks = recipe.masks;
  }
  auto store = db::Store::Open(a.db, db::Store::Role::kReadOnly);
  UnitReport report;
  try {
    report = LoadUnitReport(*store, a.serial, a.test_id, hash, masks);
  } catch (const std::out_of_range& e) {
    std::cerr << "eol report: " << e.what() << std::endl;
    return 1;
  }
  report.printed_at = db::UtcNowIso8601();
  report.printed_by_software = SoftwareVersion();
  const std::string pdf = RenderUnitReportPdf(report);
  // Written beside the target and renamed over it: a reader never sees half a report.
  const std::string tmp = a.out + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f.write(pdf.data(), static_cast<std::streamsize>(pdf.size()));
    if (!f.flush()) throw std::runtime_error(a.out + ": cannot be written");
  }
  if (std::rename(tmp.c_str(), a.out.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(a.out + ": cannot be written (rename)");
  }
  if (a.json) {
    std::cout << nlohmann::json{{"path", a.out},
                                {"serial", a.serial},
                                {"test_id", report.test.id},
                                {"outcome", analysis::ToString(report.test.outcome)},
                                {"bytes", pdf.size()}}
                     .dump()
              << std::endl;
    return 0;
  }
  std::cout << "wrote " << a.out << ": " << a.serial << " test #" << report.test.id << " "
            << analysis::ToString(report.test.outcome) << ", " << pdf.size() << " bytes\n";
  return 0;
}

}  // namespace

void AddReportCommand(CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Write the printable report of a unit as PDF: serial, verdict, reasons, recipe (id,\n"
      "version, SHA-256), station, operator, times, software versions, every measurement\n"
      "with its limits, the serial's teardown findings, and the stored curve with its limits.\n"
      "Exit: 0 written, 1 the serial has no such test, 2 usage or file error.");
  cmd->add_option("--db", args->db, "SQLite file of the station")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--serial", args->serial, "Serial number")->required();
  cmd->add_option("--out", args->out, "The PDF file to write")->required();
  cmd->add_option("--test-id", args->test_id,
                  "This test of the serial instead of its newest finished one")
      ->check(Positive());
  cmd->add_option("--recipe", args->recipe,
                  "The test's recipe file: its masks are drawn on the curve when its hash is\n"
                  "the test's")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("report", [&] { return RunReport(*args); }); });
}

}  // namespace eol::station::cli
