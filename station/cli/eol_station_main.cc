// eol-station: the station daemon alone, as deploy/eol-station.service runs it. Its options
// are those of `eol station` (station/cli/station_command.h: one parser for both). It links
// the daemon's library and no bench, emulator or offline tool (tests/tools/daemon_symbols.sh
// checks its symbols).
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <clocale>

#include "station/cli/station_command.h"
#include "station/cli/usage_errors.h"
#include "station/daemon/version.h"

int main(int argc, char** argv) {
  std::setlocale(LC_ALL, "C");  // numbers in files and JSON never depend on the locale
  spdlog::set_default_logger(spdlog::stderr_color_mt("eol"));
  CLI::App app{eol::station::cli::kStationDescription, "eol-station"};
  app.set_version_flag("--version", eol::station::SoftwareVersion());
  eol::station::cli::AddStationOptions(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // the daemon ran and chose its code (RunGuarded)
  } catch (const CLI::ParseError& e) {
    return eol::station::cli::ReportParseError(app, e);  // help, the version or the usage error
  }
  return 0;
}
