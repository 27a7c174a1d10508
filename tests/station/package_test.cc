// The Debian package: cpack builds it from the build tree and it holds the program, the
// systemd unit (Type=notify with a watchdog), the config as a conffile, recipes and page.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "../support/child_process.h"

namespace eol {
namespace {

using namespace std::chrono_literals;

TEST(DebianPackage, HoldsProgramUnitConfigRecipesAndPage) {
  const std::filesystem::path build = std::filesystem::path(EOL_BINARY).parent_path();
  eol::testing::TempDir out;
  eol::testing::ChildProcess cpack({"/usr/bin/cpack", "-G", "DEB", "-B", out.path(), "--config",
                                    (build / "CPackConfig.cmake").string()});
  const auto code = cpack.Wait(300s);
  ASSERT_TRUE(code.has_value());
  ASSERT_EQ(*code, 0) << cpack.output();
  std::string deb;
  for (const auto& e : std::filesystem::directory_iterator(out.path()))
    if (e.path().extension() == ".deb") deb = e.path();
  ASSERT_FALSE(deb.empty()) << cpack.output();

  eol::testing::ChildProcess contents({"/usr/bin/dpkg-deb", "-c", deb});
  ASSERT_EQ(contents.Wait(60s).value_or(-1), 0);
  for (const char* f :
       {"./usr/bin/eol", "./usr/bin/eol-station", "./lib/systemd/system/eol-station.service",
        "./etc/eol/station.json", "./usr/share/eol/recipes/pmsm-10pole.json",
        "./usr/share/eol/web/index.html", "./usr/share/eol/web/app.js",
        "./usr/share/eol/web/engineer.html", "./usr/share/eol/web/engineer.js",
        "./usr/share/eol/web/i18n/en.json", "./usr/share/eol/web/i18n/ja.json"})
    EXPECT_NE(contents.output().find(f), std::string::npos) << f << " missing:\n"
                                                            << contents.output();
  // The manual page, made from the program's help (cmake/ManPage.cmake).
  EXPECT_NE(contents.output().find("./usr/share/man/man1/eol.1.gz"), std::string::npos)
      << "manual page missing:\n"
      << contents.output();

  // The packaged program is stripped: "-rwxr-xr-x root/root 3564736 2026-11-24 13:30
  // ./usr/bin/eol".
  std::istringstream listing(contents.output());
  std::string line;
  long long program_bytes = -1;
  while (std::getline(listing, line)) {
    if (line.size() < 13 || line.compare(line.size() - 13, 13, "./usr/bin/eol") != 0) continue;
    std::istringstream fields(line);
    std::string perms, owner;
    fields >> perms >> owner >> program_bytes;
  }
  EXPECT_GT(program_bytes, 0) << contents.output();
  EXPECT_LT(program_bytes, 15ll * 1024 * 1024) << "the packaged program is not stripped";

  eol::testing::ChildProcess control({"/usr/bin/dpkg-deb", "-I", deb});
  ASSERT_EQ(control.Wait(60s).value_or(-1), 0);
  EXPECT_NE(control.output().find("conffiles"), std::string::npos) << control.output();
  EXPECT_NE(control.output().find("postinst"), std::string::npos);
  EXPECT_NE(control.output().find("Depends:"), std::string::npos) << "shlibdeps found no libraries";

  // The config may hold API tokens: it is installed readable by owner and group only.
  eol::testing::TempDir root;
  eol::testing::ChildProcess extract({"/usr/bin/dpkg-deb", "-x", deb, root.path()});
  ASSERT_EQ(extract.Wait(60s).value_or(-1), 0) << extract.output();
  namespace fs = std::filesystem;
  const fs::perms config = fs::status(fs::path(root.path()) / "etc/eol/station.json").permissions();
  EXPECT_EQ(config & fs::perms::others_all, fs::perms::none) << "station.json is world-readable";
  EXPECT_EQ(config & fs::perms::group_write, fs::perms::none);
}

// Issue 14: the unit is hardened; systemd's own rating of it stays below 3 ("OK").
TEST(DebianPackage, ServiceUnitIsHardened) {
  const std::string unit = std::string(EOL_SOURCE_DIR) + "/deploy/eol-station.service";
  eol::testing::ChildProcess analyze(
      {"/usr/bin/systemd-analyze", "security", "--offline=true", unit});
  ASSERT_EQ(analyze.Wait(60s).value_or(-1), 0) << analyze.output();
  const std::string out = analyze.output();
  const std::string key = "Overall exposure level for eol-station.service: ";
  const auto at = out.find(key);
  ASSERT_NE(at, std::string::npos) << out;
  const double exposure = std::stod(out.substr(at + key.size()));
  EXPECT_LT(exposure, 3.0) << out;
  // The service user reaches serial adapters and sound cards.
  std::ifstream in(unit);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("SupplementaryGroups=dialout audio"), std::string::npos);
  // It runs the daemon's own program, which links no bench or emulator (daemon_symbols.sh).
  EXPECT_NE(text.find("\nExecStart=/usr/bin/eol-station --config /etc/eol/station.json\n"),
            std::string::npos);
}

}  // namespace
}  // namespace eol
