// Shared plumbing of the `eol` subcommands.
#pragma once

#include <functional>
#include <string>

namespace eol::station::cli {

// Runs a command body; a thrown exception is printed as "eol <name>: <what>" and becomes
// exit code 2, a non-zero return becomes that exit code (CLI::RuntimeError).
void RunGuarded(const std::string& name, const std::function<int()>& body);

// An ISO 8601 time option (--from, --to) normalised to UTC (db/clock.h NormaliseIso8601);
// throws std::runtime_error naming the option, so the command exits 2.
std::string IsoOption(const std::string& option, const std::string& value);

}  // namespace eol::station::cli
