#include "station/daemon/version.h"

#include <string>

#include "eol_revision.h"  // generated at build time by cmake/GitRevision.cmake

namespace eol::station {
const char* SoftwareVersion() {
  static const std::string version = std::string(EOL_VERSION) + "+" + EOL_GIT_REVISION;
  return version.c_str();
}
}  // namespace eol::station
