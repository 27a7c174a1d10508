// CLI manners, through the built binary: every command that prints results has `--json` as a
// flag; long jobs draw a progress line with an ETA on stderr when it is a terminal (run here on
// a pseudo-terminal by tests/support/stderr_on_pty.py) and write plain lines when it is piped;
// usage errors name the unknown option first, bounds are readable, unknown names are errors
// that name the known ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
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

TEST_P(Progress, DrawnOnATerminalAndPlainWhenPiped) {
  const LongJob& job = GetParam();
  const PtyRun tty = OnTerminal(job.args);
  ASSERT_EQ(tty.code, 0) << tty.err << tty.out;
  EXPECT_NE(tty.err.find(job.line), std::string::npos) << tty.err;
  EXPECT_NE(tty.err.find(", done"), std::string::npos) << "the phase ends at 100 %\n" << tty.err;
  EXPECT_TRUE(std::regex_search(tty.err, std::regex(R"(ETA \d+ (s|min|h))"))) << tty.err;
  EXPECT_EQ(tty.out.find("\r"), std::string::npos) << "progress on stdout:\n" << tty.out;
  EXPECT_EQ(tty.out.find(job.line), std::string::npos) << "progress on stdout:\n" << tty.out;

  // Piped: plain lines (no carriage return, no terminal codes), the phase's end among them,
  // and far fewer than on the terminal (one every 10 s and the end).
  const CliRun piped = Piped(job.args);
  ASSERT_EQ(piped.code, 0) << piped.out;
  EXPECT_NE(piped.out.find(job.line), std::string::npos) << "no progress when piped\n" << piped.out;
  EXPECT_TRUE(std::regex_search(piped.out, std::regex(job.line + R"(.*, done\n)"))) << piped.out;
  EXPECT_EQ(piped.out.find("\r"), std::string::npos) << piped.out;
  EXPECT_EQ(piped.out.find("\033"), std::string::npos) << piped.out;
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

// --- Usage errors -------------------------------------------------------------------------

TEST(UsageErrors, AnUnknownOptionIsNamedBeforeAMissingRequiredOne) {
  // query requires --serial: the misspelling is the cause, not the missing option.
  const CliRun r = testing::RunEol({"query", "--db", "x.sqlite", "--serail", "A-1"}, true, 60s);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("eol query: unknown option --serail (did you mean --serial?)"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("is required"), std::string::npos) << r.out;
  // An option far from every known one gets no suggestion; an unknown command gets the nearest.
  const CliRun far = testing::RunEol({"stats", "--zzzzzzzz"}, true, 60s);
  EXPECT_EQ(far.code, 2) << far.out;
  EXPECT_NE(far.out.find("unknown option --zzzzzzzz\n"), std::string::npos) << far.out;
  const CliRun command = testing::RunEol({"qurey", "--serial", "A-1"}, true, 60s);
  EXPECT_EQ(command.code, 2) << command.out;
  EXPECT_NE(command.out.find("unknown command 'qurey' (did you mean query?)"), std::string::npos)
      << command.out;
}

TEST(UsageErrors, AnUnknownEffectNamesTheCatalogue) {
  const CliRun r = testing::RunEol(
      {"gap", "--sim", "a.csv", "--measured", "b.csv", "--effects", "gremlins"}, true, 60s);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--effects: unknown effect 'gremlins'; the effects: series_resistance, "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("fractional_inductance"), std::string::npos) << r.out;
}

TEST(UsageErrors, RangeErrorsPrintReadableBounds) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"gap", "--sim", "a.csv", "--measured", "b.csv", "--f-lo-hz", "-1"},
       "--f-lo-hz: -1 is out of range: must be >= 0"},
      {{"analyze", "--measured", "a.csv", "--clamp-pressure-bar", "0"},
       "--clamp-pressure-bar: 0 is out of range: must be > 0"},
      {{"fit-bench", "--runs", "1"}, "--runs: 1 is out of range: from 2 to 1000000"},
      {{"demo", "--defect-share", "2"}, "--defect-share: 2 is out of range: from 0 to 1"},
      {{"gap", "--sim", "a.csv", "--measured", "b.csv", "--sigma-dof", "3"},
       "3 is out of range: from 4 to 1e+12"}};
  for (const Case& c : cases) {
    const CliRun r = testing::RunEol(c.args, true, 60s);
    EXPECT_EQ(r.code, 2) << c.args[0] << ": " << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << c.args[0] << ": " << r.out;
    EXPECT_FALSE(std::regex_search(r.out, std::regex(R"(\d{13,})")))
        << c.args[0] << ": an unreadable bound\n"
        << r.out;
  }
}

// --- Commands on a station store ---------------------------------------------------------

// Two demo tests (simulated fixture) in one store, shared by the tests of this suite.
class OnAStore : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir;
    const CliRun r = testing::RunEol(
        {"demo", "--units", "2", "--db", Db(), "--port", "0", "--fixture", "sim"}, true, 300s);
    ASSERT_EQ(r.code, 0) << r.out;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string Db() { return *dir_ / "demo.sqlite"; }
  static testing::TempDir* dir_;
};
testing::TempDir* OnAStore::dir_ = nullptr;

TEST_F(OnAStore, StatsRefusesAGaugeSerialWithoutTestsAndNamesTheTestedOnes) {
  const CliRun nope = testing::RunEol({"stats", "--db", Db(), "--gauge", "NOPE"}, true, 120s);
  EXPECT_EQ(nope.code, 2) << nope.out;
  EXPECT_NE(nope.out.find("--gauge NOPE: no PASS or FAIL test of this serial"), std::string::npos)
      << nope.out;
  EXPECT_NE(nope.out.find("serials tested more than once: none"), std::string::npos) << nope.out;
  // A serial with a test is a gauge study; a reference to a measurement it lacks names those
  // it has.
  const CliRun one = testing::RunEol({"stats", "--db", Db(), "--gauge", "DEMO-1-0001"}, true, 120s);
  EXPECT_EQ(one.code, 0) << one.out;
  EXPECT_NE(one.out.find("type-1 gauge study of DEMO-1-0001: 1 tests"), std::string::npos)
      << one.out;
  const CliRun ref = testing::RunEol(
      {"stats", "--db", Db(), "--gauge", "DEMO-1-0001", "--reference", "bogus_hz=1"}, true, 120s);
  EXPECT_EQ(ref.code, 2) << ref.out;
  EXPECT_NE(ref.out.find("--reference bogus_hz: the gauge study of DEMO-1-0001 has no such"),
            std::string::npos)
      << ref.out;
  EXPECT_NE(ref.out.find("resonance_f_hz"), std::string::npos) << ref.out;
}

TEST_F(OnAStore, QueryPrintsTheLimitsItsHelpPromises) {
  const CliRun help = testing::RunEol({"query", "--help"}, true, 60s);
  ASSERT_NE(help.out.find("limits"), std::string::npos) << help.out;
  const CliRun r = testing::RunEol({"query", "--db", Db(), "--serial", "DEMO-1-0001"}, true, 60s);
  ASSERT_EQ(r.code, 0) << r.out;
  // The demo recipe judges the resonance against a window: its line shows both bounds.
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex(R"(resonance_f_hz\s+[0-9.]+ Hz\s+limits [0-9.]+ \.\. [0-9.]+ +\[PASS\])")))
      << r.out;
}

TEST_F(OnAStore, DbBenchGivesNoEtaBeforeItHasMeasuredARate) {
  // The copies phase starts with the first block done (1 of 4): its first line, at 25 % or
  // 50 %, has no rate yet, so no ETA (it read "ETA 0 s" at 50 %).
  const PtyRun r = OnTerminal({"db-bench", "--template", Db(), "--db", *dir_ / "bench.sqlite",
                               "--tests", "300", "--replicate", "4", "--queries", "20"});
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  const std::regex first(R"(eol db-bench: replicate  2/4  50%  [^\r\n\033]*)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, first)) << r.err;
  EXPECT_EQ(m.str().find("ETA"), std::string::npos) << m.str();
  EXPECT_NE(r.err.find("replicate  4/4  100%"), std::string::npos) << r.err;
}

// The store checks the file before it takes "<path>.lock" (db::Store::Open; the lock is not
// taken in CLI code): a file that is not a store is refused with nothing created beside it.
TEST(StoreFiles, ADemoOnAFileThatIsNotAStoreLeavesNoFileBesideIt) {
  testing::TempDir dir;
  const std::string text = dir / "passwd";
  std::ofstream(text) << "root:x:0:0:root:/root:/bin/bash\n";
  const CliRun r = testing::RunEol(
      {"demo", "--units", "1", "--db", text, "--port", "0", "--fixture", "sim"}, true, 120s);
  EXPECT_NE(r.code, 0) << r.out;
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, std::vector<std::string>{"passwd"}) << r.out;
}

}  // namespace
}  // namespace eol
