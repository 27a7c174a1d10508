// Shared plumbing of the `eol` subcommands.
#pragma once

#include <functional>
#include <string>

namespace eol::station::cli {

// recipes/pmsm-10pole.json beside the sources, or the installed copy.
std::string DefaultRecipePath();
// The operator page's folder (station/web), or empty when not found.
std::string DefaultWebRoot();
// Runs a command body; a thrown exception is printed as "eol <name>: <what>" and becomes
// exit code 2, a non-zero return becomes that exit code (CLI::RuntimeError).
void RunGuarded(const std::string& name, const std::function<int()>& body);

}  // namespace eol::station::cli
