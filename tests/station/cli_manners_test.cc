// CLI manners, through the built binary: every command that prints results has `--json` as a
// flag; long jobs draw a progress line with an ETA on stderr when it is a terminal (run here on
// a pseudo-terminal by tests/support/stderr_on_pty.py) and stay quiet when it is piped.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::CliRun;

// The subcommands `eol --help` lists.
std::vector<std::string> Subcommands() {
  const CliRun help = testing::RunEol({"--help"}, true, 60s);
  EXPECT_EQ(help.code, 0) << help.out;
  std::vector<std::string> names;
  const auto at = help.out.find("Subcommands:");
  EXPECT_NE(at, std::string::npos) << help.out;
  if (at == std::string::npos) return names;
  std::istringstream in(help.out.substr(at));
  const std::regex entry(R"(^  ([a-z][a-z-]*)\s)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, entry)) names.push_back(m[1]);
  }
  return names;
}

// Servers print a start line and logs, never results: they need no --json.
const std::set<std::string> kServers = {"station", "fixture-sim"};

TEST(CliManners, EveryResultPrintingCommandHasJsonAsAFlag) {
  const std::vector<std::string> commands = Subcommands();
  ASSERT_GE(commands.size(), 18u) << "the help lists fewer commands than main.cc adds";
  // A flag's help line is "  --json  description"; an option's names its value ("--json TEXT").
  const std::regex flag(R"((^|\n)\s+--json(\s{2,}|\n|$))");
  const std::regex option(R"((^|\n)\s+--json [A-Z])");
  for (const std::string& c : commands) {
    const CliRun help = testing::RunEol({c, "--help"}, true, 60s);
    ASSERT_EQ(help.code, 0) << c << ": " << help.out;
    EXPECT_FALSE(std::regex_search(help.out, option)) << c << ": --json takes a value\n"
                                                      << help.out;
    if (kServers.count(c)) continue;
    EXPECT_TRUE(std::regex_search(help.out, flag)) << c << ": no --json flag\n" << help.out;
  }
}

TEST(CliManners, NoCommandOptionIsNamedVerdict) {
  for (const std::string& c : Subcommands()) {
    const CliRun help = testing::RunEol({c, "--help"}, true, 60s);
    EXPECT_EQ(help.out.find("--verdict"), std::string::npos) << c << ": use --outcome";
  }
}

struct PtyRun {
  int code = -1;
  std::string out, err;
};

// `eol args...` with stderr on a pseudo-terminal, stdout on a pipe.
PtyRun OnTerminal(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {"/usr/bin/env", "python3",
                                   std::string(EOL_SOURCE_DIR) + "/tests/support/stderr_on_pty.py",
                                   EOL_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  ChildProcess p(argv, false);
  EXPECT_EQ(p.Wait(600s).value_or(-1), 0) << p.output();
  const auto j = nlohmann::json::parse(p.output());
  return {j["code"], j["stdout"], j["stderr"]};
}

// The same with stderr on a pipe (merged into the captured output).
CliRun Piped(const std::vector<std::string>& args) { return testing::RunEol(args, true, 600s); }

struct LongJob {
  std::vector<std::string> args;
  std::string line;  // the progress line's start
};

class Progress : public ::testing::TestWithParam<LongJob> {};

TEST_P(Progress, DrawnOnATerminalAndQuietWhenPiped) {
  const LongJob& job = GetParam();
  const PtyRun tty = OnTerminal(job.args);
  ASSERT_EQ(tty.code, 0) << tty.err << tty.out;
  EXPECT_NE(tty.err.find(job.line), std::string::npos) << tty.err;
  EXPECT_NE(tty.err.find(", done"), std::string::npos) << "the phase ends at 100 %\n" << tty.err;
  EXPECT_TRUE(std::regex_search(tty.err, std::regex(R"(ETA \d+ (s|min|h))"))) << tty.err;
  EXPECT_EQ(tty.out.find("\r"), std::string::npos) << "progress on stdout:\n" << tty.out;
  EXPECT_EQ(tty.out.find(job.line), std::string::npos) << "progress on stdout:\n" << tty.out;

  const CliRun piped = Piped(job.args);
  ASSERT_EQ(piped.code, 0) << piped.out;
  EXPECT_EQ(piped.out.find(job.line), std::string::npos) << piped.out;
  EXPECT_EQ(piped.out.find("\r"), std::string::npos) << piped.out;
  EXPECT_EQ(piped.out.find("ETA"), std::string::npos) << piped.out;
}

INSTANTIATE_TEST_SUITE_P(
    LongJobs, Progress,
    ::testing::Values(LongJob{{"fit-bench", "--runs", "6", "--check-runs", "0", "--json"},
                              "eol fit-bench: runs  "},
                      LongJob{{"production-bench", "--units", "60", "--golden-units", "40",
                               "--pod-units", "0", "--threads", "2", "--json"},
                              "eol production-bench: production units  "},
                      LongJob{{"gap-bench", "--cases", "3", "--quiet"}, "eol gap-bench: cases  "}),
    [](const ::testing::TestParamInfo<LongJob>& info) {
      std::string name = info.param.args[0];
      name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
      return name;
    });

}  // namespace
}  // namespace eol
