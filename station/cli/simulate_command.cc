// STUB, being replaced: `eol simulate`.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddSimulateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Write simulated motor data (not yet built)");
  cmd->callback([] {
    std::cerr << "simulate: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
