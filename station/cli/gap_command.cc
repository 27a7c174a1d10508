// STUB, being replaced: `eol gap`.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddGapCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("gap", "Sim-to-real gap diagnosis (not yet built)");
  cmd->callback([] {
    std::cerr << "gap: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
