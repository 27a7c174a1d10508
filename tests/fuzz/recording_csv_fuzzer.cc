// io::ReadRecordingCsv (drivers/io/recording_files.h): equal channels of finite samples at a
// finite positive rate, or FileError.
#include "drivers/io/file_error.h"
#include "drivers/io/recording_files.h"
#include "tests/fuzz/recording_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = eol::fuzz::AsFile(data, size);
  try {
    eol::fuzz::CheckRecording(eol::io::ReadRecordingCsv(path), "ReadRecordingCsv");
  } catch (const eol::io::FileError&) {
  } catch (...) {
    eol::fuzz::FailOnException("ReadRecordingCsv");
  }
  return 0;
}
