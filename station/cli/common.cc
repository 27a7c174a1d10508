#include "station/cli/common.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <stdexcept>

#include "db/clock.h"

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

std::string IsoOption(const std::string& option, const std::string& value) {
  std::string why;
  const auto t = db::NormaliseIso8601(value, &why);
  if (!t) throw std::runtime_error(option + ": " + why);
  return *t;
}

}  // namespace eol::station::cli
