// Shared plumbing of the `eol` subcommands.
#pragma once

#include <functional>
#include <string>

namespace eol::station::cli {

// Runs a command body; a thrown exception is printed as "eol <name>: <what>" and becomes
// exit code 2, a non-zero return becomes that exit code (CLI::RuntimeError).
void RunGuarded(const std::string& name, const std::function<int()>& body);

}  // namespace eol::station::cli
