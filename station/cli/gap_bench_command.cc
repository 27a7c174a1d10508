// STUB, being replaced: `eol gap-bench`.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddGapBenchCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("gap-bench", "Blind benchmark of the gap diagnosis (not yet built)");
  cmd->callback([] {
    std::cerr << "gap-bench: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
