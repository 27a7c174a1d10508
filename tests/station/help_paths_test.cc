// No `--help` shows a path of the machine the program was built on: defaults come from the
// working directory or the installed program's prefix (station/data_files.h), and the
// help says where they are looked for.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/eol_cli.h"

namespace eol {
namespace {

using namespace std::chrono_literals;

// The subcommand names listed under "SUBCOMMANDS:" in `eol --help`.
std::vector<std::string> Subcommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help);
  std::string line;
  bool in_list = false;
  while (std::getline(in, line)) {
    if (line.rfind("SUBCOMMANDS:", 0) == 0 || line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
      continue;
    }
    if (!in_list) continue;
    if (line.empty() || line[0] != ' ') break;
    std::istringstream words(line);
    std::string name;
    if (words >> name) names.push_back(name);
  }
  return names;
}

TEST(HelpPaths, NoHelpShowsTheBuildMachinesPaths) {
  const std::string source = std::filesystem::weakly_canonical(EOL_SOURCE_DIR).string();
  const std::string build =
      std::filesystem::weakly_canonical(std::filesystem::path(EOL_BINARY).parent_path()).string();
  const testing::CliRun top = testing::RunEol({"--help"}, true, 30s);
  ASSERT_EQ(top.code, 0) << top.out;
  const std::vector<std::string> subs = Subcommands(top.out);
  ASSERT_GE(subs.size(), 10u) << "could not read the subcommands from:\n" << top.out;
  std::vector<std::pair<std::string, std::string>> helps = {{"eol", top.out}};
  for (const std::string& sub : subs) {
    const testing::CliRun r = testing::RunEol({sub, "--help"}, true, 30s);
    EXPECT_EQ(r.code, 0) << sub << ":\n" << r.out;
    helps.emplace_back("eol " + sub, r.out);
  }
  for (const auto& [what, text] : helps) {
    EXPECT_EQ(text.find(source), std::string::npos) << what << " --help shows " << source;
    EXPECT_EQ(text.find(build), std::string::npos) << what << " --help shows " << build;
    EXPECT_NE(text.find("Default files:"), std::string::npos)
        << what << " --help does not say where default files come from";
  }
}

}  // namespace
}  // namespace eol
