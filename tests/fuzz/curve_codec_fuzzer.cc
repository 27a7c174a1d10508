// db::DecodeCurve (db/curve_codec.h): a curve with consistent arrays, or std::invalid_argument;
// what it returns encodes again and reads back with the same grid and line count.
#include <stdexcept>
#include <string>
#include <string_view>

#include "db/curve_codec.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const eol::db::Curve c = eol::db::DecodeCurve(bytes, "fuzz");
    const std::size_t n = c.freq_hz.size();
    if (n == 0 || c.re.size() != n || c.im.size() != n || !(c.sigma.empty() || c.sigma.size() == n))
      eol::fuzz::Finding("DecodeCurve returned arrays of different lengths");
    const eol::db::Curve again = eol::db::DecodeCurve(eol::db::EncodeCurve(c), "fuzz");
    if (again.freq_hz.size() != n || again.sigma.size() != c.sigma.size() || again.unit != c.unit)
      eol::fuzz::Finding("a decoded curve did not survive encoding again");
  } catch (const std::invalid_argument&) {
  } catch (...) {
    eol::fuzz::FailOnException("DecodeCurve");
  }
  return 0;
}
