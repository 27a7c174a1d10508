// io::ReadFrfCsv (drivers/io/frf_files.h): an Frf that keeps its invariants, or FileError.
#include <string>

#include "drivers/io/file_error.h"
#include "drivers/io/frf_files.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = eol::fuzz::AsFile(data, size);
  try {
    const eol::analysis::Frf frf = eol::io::ReadFrfCsv(path);
    std::string why;
    if (!frf.Validate(&why)) eol::fuzz::Finding("ReadFrfCsv returned an invalid Frf: " + why);
    if (frf.size() == 0) eol::fuzz::Finding("ReadFrfCsv returned an empty Frf");
  } catch (const eol::io::FileError&) {
  } catch (...) {
    eol::fuzz::FailOnException("ReadFrfCsv");
  }
  return 0;
}
