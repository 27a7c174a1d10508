// STUB, being replaced: `eol query`.
#include <iostream>

#include "station/cli/commands.h"

namespace eol::station::cli {

void AddQueryCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("query", "History of a serial number (not yet built)");
  cmd->callback([] {
    std::cerr << "query: not built yet\n";
    throw CLI::RuntimeError(2);
  });
}

}  // namespace eol::station::cli
