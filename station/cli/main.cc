// eol: the end-of-line test station for permanent-magnet motors.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <clocale>
#include <string>

#include "station/cli/commands.h"
#include "station/cli/usage_errors.h"
#include "station/daemon/data_files.h"
#include "station/daemon/version.h"

int main(int argc, char** argv) {
  std::setlocale(LC_ALL, "C");  // numbers in files and JSON never depend on the locale
  // Logs go to stderr: stdout carries results (unit lines, JSON summaries).
  spdlog::set_default_logger(spdlog::stderr_color_mt("eol"));
  CLI::App app{
      "eol - end-of-line test station for permanent-magnet motors.\n"
      "Clamps the shaft, excites a stator phase pair with a multisine, estimates the impedance\n"
      "Z(f), fits the clamped rotor's torsional resonance and judges it against the recipe.",
      "eol"};  // named, so usage lines never show the path the program was started by
  app.set_version_flag("--version", eol::station::SoftwareVersion());
  app.require_subcommand(1);
  eol::station::cli::AddDemoCommand(app);
  eol::station::cli::AddStationCommand(app);
  eol::station::cli::AddFixtureSimCommand(app);
  eol::station::cli::AddAnalyzeCommand(app);
  eol::station::cli::AddSimulateCommand(app);
  eol::station::cli::AddFitBenchCommand(app);
  eol::station::cli::AddGapCommand(app);
  eol::station::cli::AddGapBenchCommand(app);
  eol::station::cli::AddQueryCommand(app);
  eol::station::cli::AddExportCommand(app);
  eol::station::cli::AddSafetyBenchCommand(app);
  eol::station::cli::AddStatsCommand(app);
  eol::station::cli::AddCalibrateCommand(app);
  eol::station::cli::AddTeachCommand(app);
  eol::station::cli::AddDetectabilityCommand(app);
  eol::station::cli::AddProductionBenchCommand(app);
  eol::station::cli::AddHttpBenchCommand(app);
  eol::station::cli::AddCycleBenchCommand(app);
  eol::station::cli::AddDbBenchCommand(app);
  eol::station::cli::AddDesignExcitationCommand(app);
  eol::station::cli::AddRecipeNewCommand(app);
  eol::station::cli::AddPodCommand(app);
  eol::station::cli::AddRecipeApproveCommand(app);
  eol::station::cli::AddPlantBenchCommand(app);
  eol::station::cli::AddTeardownCommand(app);
  eol::station::cli::AddReportCommand(app);
  // Default files (recipe, operator page, SciPy peer) come from the working directory or the
  // installed program's prefix, never from the machine the program was built on.
  const std::string defaults =
      std::string("Default files: ") + eol::station::kDefaultsSearchHelp + ".";
  app.footer(defaults);
  for (CLI::App* sub : app.get_subcommands({})) sub->footer(defaults);
  // Exit codes: 0 done; 1 the command's negative answer (e.g. a serial with no tests, a
  // drift alarm; see each command's help); 2 a usage error (unknown option, missing or
  // malformed argument, a file that does not exist) or a failure the command names.
  // CLI11 would exit 101-115 for usage errors; those all become 2. Unknown options are named
  // first, with the nearest known one (usage_errors.h).
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // the command ran and chose its code (RunGuarded)
  } catch (const CLI::ParseError& e) {
    return eol::station::cli::ReportParseError(app, e);  // help, the version or the usage error
  }
  return 0;
}
