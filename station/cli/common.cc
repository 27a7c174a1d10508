#include "station/cli/common.h"

#include <CLI/CLI.hpp>
#include <iostream>

namespace eol::station::cli {
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
