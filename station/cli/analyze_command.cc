// STUB, being replaced: `eol analyze`.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddAnalyzeCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("analyze", "Analyse a measured FRF or raw recording (not yet built)");
  cmd->callback([] {
    std::cerr << "analyze: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
