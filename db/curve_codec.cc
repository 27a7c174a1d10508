#include "db/curve_codec.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace eol::db {
namespace {

constexpr char kMagic[4] = {'E', 'O', 'L', 'C'};
constexpr std::uint8_t kVersion = 1;
constexpr std::uint8_t kHasSigma = 1, kUniformGrid = 2, kFloat64Values = 4;
constexpr double kGridTolerance = 1e-9;    // relative, per line
constexpr double kSigmaShare = 1e-3;       // of a line's sigma
constexpr double kRelativeNoSigma = 1e-6;  // of the value, for curves without sigma

// The host is little-endian (x86-64 and arm64 Debian); memcpy keeps the bytes as they are.
static_assert(std::endian::native == std::endian::little, "the codec writes little-endian");

template <typename T>
void Put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}
  template <typename T>
  T Get(const char* what) {
    if (bytes_.size() - pos_ < sizeof(T))
      throw std::invalid_argument(std::string("truncated curve (") + what + ")");
    T v;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string_view Take(std::size_t n, const char* what) {
    if (bytes_.size() - pos_ < n)
      throw std::invalid_argument(std::string("truncated curve (") + what + ")");
    const std::string_view s = bytes_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  std::size_t left() const { return bytes_.size() - pos_; }

 private:
  std::string_view bytes_;
  std::size_t pos_ = 0;
};

bool GridIsUniform(const std::vector<double>& f) {
  if (f.size() < 2) return false;
  const double step = (f.back() - f.front()) / static_cast<double>(f.size() - 1);
  for (std::size_t k = 0; k < f.size(); ++k) {
    const double at = f.front() + static_cast<double>(k) * step;
    if (!(std::abs(at - f[k]) <= kGridTolerance * std::abs(f[k]))) return false;
  }
  return true;
}

bool Float32Keeps(const Curve& c) {
  for (double s : c.sigma) {
    if (!std::isfinite(s)) return false;
    const double err = std::abs(static_cast<double>(static_cast<float>(s)) - s);
    if (!(err <= kRelativeNoSigma * std::abs(s))) return false;  // e.g. below float's range
  }
  for (std::size_t k = 0; k < c.re.size(); ++k) {
    for (double v : {c.re[k], c.im[k]}) {
      if (!std::isfinite(v)) return false;
      const double err = std::abs(static_cast<double>(static_cast<float>(v)) - v);
      const double allowed =
          c.sigma.empty() ? kRelativeNoSigma * std::abs(v) : kSigmaShare * c.sigma[k];
      if (!(err <= allowed)) return false;
    }
  }
  return true;
}

}  // namespace

std::string EncodeCurve(const Curve& c) {
  const std::size_t n = c.freq_hz.size();
  if (n == 0 || n > kMaxCurveLines)
    throw std::invalid_argument("curve '" + c.name + "': " + std::to_string(n) + " lines (1 to " +
                                std::to_string(kMaxCurveLines) + ")");
  if (c.re.size() != n || c.im.size() != n || !(c.sigma.empty() || c.sigma.size() == n))
    throw std::invalid_argument("curve '" + c.name +
                                "': freq_hz, re, im and sigma differ in length");
  if (c.unit.size() > 0xFFFF)
    throw std::invalid_argument("curve '" + c.name + "': unit longer than 65535 bytes");
  const bool uniform = GridIsUniform(c.freq_hz);
  const bool wide = !Float32Keeps(c);
  std::uint8_t flags = 0;
  if (!c.sigma.empty()) flags |= kHasSigma;
  if (uniform) flags |= kUniformGrid;
  if (wide) flags |= kFloat64Values;

  std::string out(kMagic, sizeof kMagic);
  Put<std::uint8_t>(out, kVersion);
  Put<std::uint8_t>(out, flags);
  Put<std::uint16_t>(out, static_cast<std::uint16_t>(c.unit.size()));
  out += c.unit;
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(n));
  if (uniform) {
    Put<double>(out, c.freq_hz.front());
    Put<double>(out, (c.freq_hz.back() - c.freq_hz.front()) / static_cast<double>(n - 1));
  } else {
    for (double f : c.freq_hz) Put<double>(out, f);
  }
  auto values = [&](const std::vector<double>& v) {
    for (double x : v) {
      if (wide)
        Put<double>(out, x);
      else
        Put<float>(out, static_cast<float>(x));
    }
  };
  values(c.re);
  values(c.im);
  values(c.sigma);
  return out;
}

Curve DecodeCurve(std::string_view bytes, const std::string& name) {
  Reader in(bytes);
  if (in.Take(sizeof kMagic, "magic") != std::string_view(kMagic, sizeof kMagic))
    throw std::invalid_argument("not an encoded curve (no EOLC magic)");
  const auto version = in.Get<std::uint8_t>("version");
  if (version != kVersion)
    throw std::invalid_argument("encoded curve version " + std::to_string(version) +
                                " (this program reads " + std::to_string(kVersion) + ")");
  const auto flags = in.Get<std::uint8_t>("flags");
  if (flags & ~(kHasSigma | kUniformGrid | kFloat64Values))
    throw std::invalid_argument("encoded curve has unknown flags " + std::to_string(flags));
  Curve c;
  c.name = name;
  c.unit = std::string(in.Take(in.Get<std::uint16_t>("unit length"), "unit"));
  const std::uint32_t n = in.Get<std::uint32_t>("line count");
  if (n == 0 || n > kMaxCurveLines)
    throw std::invalid_argument("encoded curve has " + std::to_string(n) + " lines");
  // Checked before allocating: the bytes must hold what the header promises.
  const std::size_t value_bytes = (flags & kFloat64Values) ? 8 : 4;
  const std::size_t need = ((flags & kUniformGrid) ? 16 : 8 * std::size_t{n}) +
                           ((flags & kHasSigma) ? 3 : 2) * value_bytes * n;
  if (in.left() != need)
    throw std::invalid_argument("encoded curve of " + std::to_string(n) + " lines needs " +
                                std::to_string(need) + " bytes after its header, has " +
                                std::to_string(in.left()));
  c.freq_hz.resize(n);
  if (flags & kUniformGrid) {
    const double first = in.Get<double>("grid"), step = in.Get<double>("grid");
    for (std::uint32_t k = 0; k < n; ++k) c.freq_hz[k] = first + static_cast<double>(k) * step;
  } else {
    for (double& f : c.freq_hz) f = in.Get<double>("frequencies");
  }
  auto values = [&](std::vector<double>& v, const char* what) {
    v.resize(n);
    for (double& x : v)
      x = (flags & kFloat64Values) ? in.Get<double>(what)
                                   : static_cast<double>(in.Get<float>(what));
  };
  values(c.re, "re");
  values(c.im, "im");
  if (flags & kHasSigma) values(c.sigma, "sigma");
  return c;
}

}  // namespace eol::db
