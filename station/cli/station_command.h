// The daemon's options and run, shared by `eol station` (the tool's subcommand) and
// `eol-station` (the daemon's own program, station/cli/eol_station_main.cc): both parse the
// same options with the same checks and run the same code, so the alias never drifts.
#pragma once

#include <CLI/CLI.hpp>

namespace eol::station::cli {

// What the daemon does, for its help.
extern const char* const kStationDescription;

// Adds --config FILE (required), --web-root DIR and --init-store to `cmd`, and as its
// callback runs the station until SIGTERM or SIGINT. Exit codes: 0 stopped, 78 a
// configuration error, 65 a store refused, 2 any other failure (RunGuarded).
void AddStationOptions(CLI::App& cmd);

}  // namespace eol::station::cli
