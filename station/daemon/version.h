#pragma once
namespace eol::station {
// The software version written into every record: the project version and the git commit
// it was built from when known.
const char* SoftwareVersion();
}  // namespace eol::station
