// STUB, being replaced: `eol export`.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddExportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("export", "Export records as CSV or JSON (not yet built)");
  cmd->callback([] {
    std::cerr << "export: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
