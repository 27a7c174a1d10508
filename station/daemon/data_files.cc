#include "station/daemon/data_files.h"

#include <filesystem>
#include <initializer_list>

namespace eol::station {
namespace {

namespace fs = std::filesystem;

std::string FirstExisting(std::initializer_list<std::string> candidates) {
  for (const std::string& c : candidates) {
    std::error_code ec;
    if (!c.empty() && fs::exists(c, ec)) return c;
  }
  return "";
}

std::string Installed(const std::string& relative) {
  const std::string dir = InstalledDataDir();
  return dir.empty() ? "" : dir + "/" + relative;
}

}  // namespace

std::string InstalledDataDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec || exe.empty()) return "";
  return (exe.parent_path().parent_path() / "share" / "eol").string();
}

std::string DefaultRecipePath(const std::string& name) {
  const std::string local = "recipes/" + name;
  const std::string found =
      FirstExisting({local, "/var/lib/eol/recipes/" + name, Installed("recipes/" + name)});
  return found.empty() ? local : found;
}

std::string DefaultWebRoot() {
  return FirstExisting({"station/web/dist", "station/web", Installed("web")});
}

std::string DefaultScipyPipelineScript() {
  const std::string local = "deploy/bench/fit_pipeline_scipy.py";
  const std::string found = FirstExisting({local, Installed("bench/fit_pipeline_scipy.py")});
  return found.empty() ? local : found;
}

}  // namespace eol::station
