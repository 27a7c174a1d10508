// STUB, being replaced: `eol fixture-sim` serves the simulated bench over Modbus and CAN.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddFixtureSimCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("fixture-sim", "Fixture emulator (not yet built)");
  cmd->callback([] {
    std::cerr << "fixture-sim: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
