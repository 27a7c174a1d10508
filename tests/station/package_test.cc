// The Debian package: cpack builds it from the build tree and it holds the program, the
// systemd unit (Type=notify with a watchdog), the config as a conffile, recipes and page.
#include <gtest/gtest.h>

#include <filesystem>
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
  for (const char* f : {"./usr/bin/eol", "./lib/systemd/system/eol-station.service",
                        "./etc/eol/station.json", "./usr/share/eol/recipes/pmsm-10pole.json",
                        "./usr/share/eol/web/index.html", "./usr/share/eol/web/app.js"})
    EXPECT_NE(contents.output().find(f), std::string::npos) << f << " missing:\n"
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
}

}  // namespace
}  // namespace eol
