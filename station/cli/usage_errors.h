// What `eol` prints for a usage error (CLI::ParseError), before CLI11's own message:
//   - an unknown option is named first, with the nearest known option of its command, even
//     when a required option is missing too (CLI11 checks "required" before extras):
//       eol demo: unknown option --serail (did you mean --serial?)
//   - an unknown command is named with the nearest command:
//       eol: unknown command 'dmeo' (did you mean demo?)
// Anything else is CLI11's message. Help and --version print as CLI11 does.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace eol::station::cli {

// Prints the error (or help, version) and returns the exit code: 0 for help and version,
// 2 for every usage error.
int ReportParseError(CLI::App& app, const CLI::ParseError& e);

// The candidate nearest to `word` by edit distance, or "" when none is close (more than a
// third of the word, and at least 2 edits, away).
std::string Nearest(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace eol::station::cli
