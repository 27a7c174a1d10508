// Shared plumbing of the `eol` subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace eol::station::cli {

// Runs a command body; a thrown exception is printed as "eol <name>: <what>" and becomes
// exit code 2, a non-zero return becomes that exit code (CLI::RuntimeError).
void RunGuarded(const std::string& name, const std::function<int()>& body);

// An ISO 8601 time option (--from, --to) normalised to UTC (db/clock.h NormaliseIso8601);
// throws std::runtime_error naming the option, so the command exits 2.
std::string IsoOption(const std::string& option, const std::string& value);

// Number checks for options, in place of CLI::Range, CLI::PositiveNumber and
// CLI::NonNegativeNumber (whose messages print std::to_string of the bounds: 309 digits for
// numeric_limits<double>::max). Help and errors print whole bounds below 1e9 in full, others
// with %g:
//   --runs: 0 is out of range: from 2 to 1000000
//   --period-s: -1 is out of range: must be >= 0
CLI::Validator Between(double lo, double hi);
CLI::Validator Positive();     // > 0
CLI::Validator NonNegative();  // >= 0

}  // namespace eol::station::cli
