// No `--help` shows a path of the machine the program was built on: defaults come from the
// working directory or the installed program's prefix (station/daemon/data_files.h), and the
// help says where they are looked for. Every `--help` names only options that exist (its
// command's, or those of a command it cites as `eol NAME`), files of the source tree that exist,
// Markdown headings that exist, and `eol gap --help` the whole effect catalogue.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/model/effects.h"
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
    // "  demo   Run ...": a name two spaces in; a description's wrapped lines are further in.
    std::smatch m;
    if (std::regex_search(line, m, std::regex(R"(^  ([a-z][a-z-]*)(\s|$))"))) names.push_back(m[1]);
  }
  return names;
}

// "eol" and "eol SUB" -> its --help.
std::map<std::string, std::string> AllHelps() {
  std::map<std::string, std::string> helps;
  const testing::CliRun top = testing::RunEol({"--help"}, true, 30s);
  EXPECT_EQ(top.code, 0) << top.out;
  helps["eol"] = top.out;
  for (const std::string& sub : Subcommands(top.out)) {
    const testing::CliRun r = testing::RunEol({sub, "--help"}, true, 30s);
    EXPECT_EQ(r.code, 0) << sub << ":\n" << r.out;
    helps["eol " + sub] = r.out;
  }
  return helps;
}

// The options a help lists under "Options:" ("  -h,--help ...", "  --db TEXT ...").
std::set<std::string> ListedOptions(const std::string& help) {
  std::set<std::string> names;
  const auto at = help.find("Options:");
  if (at == std::string::npos) return names;
  std::istringstream in(help.substr(at));
  const std::regex entry(R"(^  (?:-\w,)?(--[a-z][a-z0-9-]*))");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, entry)) names.insert(m[1]);
  }
  return names;
}

// A Markdown heading's GitHub anchor: lower case, punctuation dropped, spaces to '-'.
std::string Anchor(const std::string& heading) {
  std::string a;
  for (const char c : heading) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')
      a += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    else if (c == ' ')
      a += '-';
  }
  return a;
}

// The headings of a Markdown file ("## Export schema" -> "Export schema").
std::set<std::string> Headings(const std::string& path) {
  std::set<std::string> headings;
  std::ifstream in(path);
  const std::regex heading(R"(^#+\s+(.*\S)\s*$)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, heading)) headings.insert(m[1]);
  }
  return headings;
}

TEST(HelpNames, OnlyOptionsThatExist) {
  const std::map<std::string, std::string> helps = AllHelps();
  ASSERT_GE(helps.size(), 10u);
  std::map<std::string, std::set<std::string>> options;
  for (const auto& [what, text] : helps) options[what] = ListedOptions(text);
  ASSERT_TRUE(options["eol query"].count("--serial")) << helps.at("eol query");
  const std::regex mention(R"(--[a-z][a-z0-9-]*)");
  for (const auto& [what, text] : helps) {
    const std::string& help_text = text;
    for (std::sregex_iterator it(help_text.begin(), help_text.end(), mention), end; it != end;
         ++it) {
      const std::string name = it->str();
      if (options[what].count(name) || options["eol"].count(name)) continue;
      // An option of another command the help cites by name ("`eol teach --golden`"); the
      // list of `eol --help` describes every command.
      bool cited = false;
      for (const auto& [other, names] : options)
        cited = cited || (other != "eol" && names.count(name) &&
                          (what == "eol" || help_text.find(other + " ") != std::string::npos));
      EXPECT_TRUE(cited) << what << " --help names " << name
                         << ", an option neither it nor a command it cites has";
    }
  }
}

TEST(HelpNames, OnlyFilesAndHeadingsThatExist) {
  const std::filesystem::path source = EOL_SOURCE_DIR;
  const std::regex path(
      R"((?:^|[\s(`'"])((?:analysis|cmake|db|deploy|drivers|recipes|station|tests)/[A-Za-z0-9_./-]*[A-Za-z0-9_]|README\.md))");
  const std::regex cited_heading(R"re(([A-Za-z0-9_./-]+\.md),\s+"([^"]+)")re");
  const std::regex cited_anchor(R"(([A-Za-z0-9_./-]+\.md)#([a-z0-9_-]+))");
  int files = 0, headings = 0;
  for (const auto& [what, text] : AllHelps()) {
    for (std::sregex_iterator it(text.begin(), text.end(), path), end; it != end; ++it) {
      ++files;
      EXPECT_TRUE(std::filesystem::exists(source / (*it)[1].str()))
          << what << " --help names " << (*it)[1] << ", which is not in the source tree";
    }
    for (std::sregex_iterator it(text.begin(), text.end(), cited_heading), end; it != end; ++it) {
      ++headings;
      EXPECT_TRUE(Headings(source / (*it)[1].str()).count((*it)[2]))
          << what << " --help cites the heading \"" << (*it)[2] << "\" of " << (*it)[1]
          << ", which has none such";
    }
    for (std::sregex_iterator it(text.begin(), text.end(), cited_anchor), end; it != end; ++it) {
      ++headings;
      std::set<std::string> anchors;
      for (const std::string& h : Headings(source / (*it)[1].str())) anchors.insert(Anchor(h));
      EXPECT_TRUE(anchors.count((*it)[2]))
          << what << " --help links " << (*it)[0] << ", a heading that does not exist";
    }
  }
  EXPECT_GE(files, 5) << "the helps name fewer files than they did";
  EXPECT_GE(headings, 1) << "export --help cites the export schema's heading";
}

TEST(HelpNames, GapListsTheWholeEffectCatalogueAndNothingElse) {
  const testing::CliRun gap = testing::RunEol({"gap", "--help"}, true, 30s);
  ASSERT_EQ(gap.code, 0) << gap.out;
  for (const analysis::EffectKind kind : analysis::EffectsFor(analysis::Quantity::kImpedanceOhm))
    EXPECT_NE(gap.out.find(analysis::ToString(kind)), std::string::npos)
        << "eol gap --help does not name " << analysis::ToString(kind) << "\n"
        << gap.out;
  // The list: "The effects (or a pair of them):\n  a, b, ...\nfor impedance".
  std::smatch m;
  ASSERT_TRUE(std::regex_search(gap.out, m, std::regex(R"(pair of them\):\s+([a-z_, ]+))")))
      << gap.out;
  std::istringstream list(m[1].str());
  int listed = 0;
  for (std::string name; std::getline(list, name, ',');) {
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    ++listed;
    EXPECT_TRUE(analysis::ParseEffectKind(name)) << "eol gap --help lists '" << name << "'";
  }
  EXPECT_EQ(listed, analysis::kEffectKindCount);
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
