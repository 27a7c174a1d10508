#include "station/cli/common.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

namespace eol::station::cli {
namespace {

std::string FirstExisting(std::initializer_list<std::string> candidates) {
  for (const std::string& c : candidates)
    if (std::filesystem::exists(c)) return c;
  return "";
}

}  // namespace

std::string DefaultRecipePath() {
  const std::string found =
      FirstExisting({std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json",
                     "/var/lib/eol/recipes/pmsm-10pole.json", "/usr/share/eol/recipes/pmsm-10pole.json"});
  return found.empty() ? "recipes/pmsm-10pole.json" : found;
}

std::string DefaultWebRoot() {
  return FirstExisting({std::string(EOL_SOURCE_DIR) + "/station/web/dist",
                        std::string(EOL_SOURCE_DIR) + "/station/web", "/usr/share/eol/web"});
}

void RunGuarded(const std::string& name, const std::function<int()>& body) {
  int code = 0;
  try {
    code = body();
  } catch (const std::exception& e) {
    std::cerr << "eol " << name << ": " << e.what() << std::endl;
    throw CLI::RuntimeError(2);
  }
  if (code != 0) throw CLI::RuntimeError(code);
}

}  // namespace eol::station::cli
