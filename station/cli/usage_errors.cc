#include "station/cli/usage_errors.h"

#include <algorithm>
#include <cctype>
#include <iostream>

namespace eol::station::cli {
namespace {

std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// "-x", "--name" or "--name=value"; not "-", "--", nor a negative number ("-5", "-.5").
bool LooksLikeOption(const std::string& arg) {
  if (arg.size() < 2 || arg[0] != '-' || arg == "--") return false;
  const char c = arg[1];
  return !(std::isdigit(static_cast<unsigned char>(c)) || c == '.');
}

std::vector<std::string> OptionNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* o : app.get_options()) {
    for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : o->get_snames()) names.push_back("-" + n);
  }
  return names;
}

std::string Prefix(const CLI::App& app, const CLI::App* sub) {
  return sub == &app ? "eol" : "eol " + sub->get_name();
}

// Names every unknown option among what CLI11 left over; false when there is none.
bool ReportUnknownOptions(const CLI::App& app, const CLI::App* sub) {
  std::vector<std::string> unknown;
  for (const std::string& arg : app.remaining(true))
    if (LooksLikeOption(arg)) unknown.push_back(arg.substr(0, arg.find('=')));
  if (unknown.empty()) return false;
  const std::vector<std::string> known = OptionNames(*sub);
  for (const std::string& u : unknown) {
    const std::string near = Nearest(u, known);
    std::cerr << Prefix(app, sub) << ": unknown option " << u
              << (near.empty() ? "" : " (did you mean " + near + "?)") << "\n";
  }
  std::cerr << "Run '" << Prefix(app, sub) << " --help' for its options.\n";
  return true;
}

// An unknown command: the first word CLI11 left over when no command was recognised.
bool ReportUnknownCommand(const CLI::App& app) {
  const std::vector<std::string> left = app.remaining(false);
  if (left.empty() || LooksLikeOption(left.front())) return false;
  std::vector<std::string> commands;
  for (const CLI::App* s : app.get_subcommands({})) commands.push_back(s->get_name());
  const std::string near = Nearest(left.front(), commands);
  std::cerr << "eol: unknown command '" << left.front() << "'"
            << (near.empty() ? "" : " (did you mean " + near + "?)")
            << "\nRun 'eol --help' for the commands.\n";
  return true;
}

}  // namespace

std::string Nearest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const std::string& c : candidates) {
    const std::size_t d = EditDistance(word, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return best;
}

int ReportParseError(CLI::App& app, const CLI::ParseError& e) {
  if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
  const std::vector<CLI::App*> parsed = app.get_subcommands();
  const CLI::App* sub = parsed.empty() ? &app : parsed.front();
  if (parsed.empty() && ReportUnknownCommand(app)) return 2;
  if (ReportUnknownOptions(app, sub)) return 2;
  app.exit(e);  // CLI11's message and "Run with --help for more information."
  return 2;
}

}  // namespace eol::station::cli
