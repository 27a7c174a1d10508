// STUB, being replaced: `eol fit-bench`.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddFitBenchCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("fit-bench", "Benchmark of the identification engine (not yet built)");
  cmd->callback([] {
    std::cerr << "fit-bench: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
