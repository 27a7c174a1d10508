// io::ReadWavRecording (drivers/io/recording_files.h): equal channels of finite samples at a
// finite positive rate with the gains as full scales, or FileError.
#include "drivers/io/file_error.h"
#include "drivers/io/recording_files.h"
#include "tests/fuzz/recording_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = eol::fuzz::AsFile(data, size);
  try {
    const eol::analysis::Recording r = eol::io::ReadWavRecording(path, 10.0, 5.0);
    eol::fuzz::CheckRecording(r, "ReadWavRecording");
    if (r.voltage_full_scale_v != 10.0 || r.current_full_scale_a != 5.0)
      eol::fuzz::Finding("ReadWavRecording: full scales are not the gains");
  } catch (const eol::io::FileError&) {
  } catch (...) {
    eol::fuzz::FailOnException("ReadWavRecording");
  }
  return 0;
}
