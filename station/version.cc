#include "station/version.h"

namespace eol::station {
const char* SoftwareVersion() { return EOL_VERSION; }
}  // namespace eol::station
