#include "db/last_verdict.h"

#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string_view>

namespace eol::db {
namespace {

constexpr std::string_view kPrefix = "eol-last-verdict 1 ";
constexpr std::string_view kCrc = " crc=";
constexpr std::size_t kMaxSerialBytes = 64;

std::uint32_t Crc(std::string_view text) {
  return static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(text.data()), static_cast<uInt>(text.size())));
}

std::string Line(const LastVerdict& v) {
  std::string serial = v.serial.substr(0, kMaxSerialBytes);
  for (char& c : serial)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  std::string line = std::string(kPrefix) + "test=" + std::to_string(v.test_id) +
                     " outcome=" + v.outcome + " finished=" + v.finished_at + " serial=" + serial;
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08x", Crc(line));
  return line + std::string(kCrc) + crc;
}

// The value of "key=" up to the next space, in `line` after `from`; nullopt when absent.
std::optional<std::string_view> Field(std::string_view line, std::string_view key) {
  const std::size_t at = line.find(" " + std::string(key) + "=");
  if (at == std::string_view::npos) return std::nullopt;
  const std::size_t begin = at + key.size() + 2;
  const std::size_t end = line.find(' ', begin);
  return line.substr(begin, end == std::string_view::npos ? line.size() - begin : end - begin);
}

std::optional<LastVerdict> ParseSlot(std::string_view slot) {
  const std::size_t end = slot.find_last_not_of(" \n");
  if (end == std::string_view::npos) return std::nullopt;
  const std::string_view line = slot.substr(0, end + 1);
  const std::size_t crc_at = line.rfind(kCrc);
  if (line.substr(0, kPrefix.size()) != kPrefix || crc_at == std::string_view::npos)
    return std::nullopt;
  const std::string_view body = line.substr(0, crc_at);
  std::uint32_t crc = 0;
  const std::string_view hex = line.substr(crc_at + kCrc.size());
  const auto [p, ec] = std::from_chars(hex.data(), hex.data() + hex.size(), crc, 16);
  if (ec != std::errc() || p != hex.data() + hex.size() || crc != Crc(body)) return std::nullopt;
  LastVerdict v;
  const auto id = Field(body, "test");
  const auto outcome = Field(body, "outcome");
  const auto finished = Field(body, "finished");
  const std::size_t serial_at = body.find(" serial=");
  if (!id || !outcome || !finished || serial_at == std::string_view::npos) return std::nullopt;
  const auto [q, ec2] = std::from_chars(id->data(), id->data() + id->size(), v.test_id);
  if (ec2 != std::errc() || q != id->data() + id->size() || v.test_id <= 0) return std::nullopt;
  v.outcome = std::string(*outcome);
  v.finished_at = std::string(*finished);
  v.serial = std::string(body.substr(serial_at + 8));
  return v;
}

}  // namespace

std::string LastVerdictPath(const std::string& store_path) { return store_path + ".last-verdict"; }

std::optional<LastVerdict> ReadLastVerdict(const std::string& path, std::string* problem) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) return std::nullopt;
  std::optional<LastVerdict> newest;
  for (std::size_t at = 0; at < bytes.size(); at += kLastVerdictSlotBytes) {
    const std::optional<LastVerdict> v =
        ParseSlot(std::string_view(bytes).substr(at, kLastVerdictSlotBytes));
    if (v && (!newest || v->test_id > newest->test_id)) newest = v;
  }
  if (!newest)
    *problem = path + " holds no valid entry (" + std::to_string(bytes.size()) +
               " bytes): the newest acknowledged verdict is unknown";
  return newest;
}

std::string WriteLastVerdict(int fd, const LastVerdict& v) {
  std::string slot = Line(v);
  slot.resize(kLastVerdictSlotBytes - 1, ' ');
  slot += '\n';
  const off_t offset = static_cast<off_t>(v.test_id % 2) * kLastVerdictSlotBytes;
  const ssize_t n = ::pwrite(fd, slot.data(), slot.size(), offset);
  if (n != static_cast<ssize_t>(slot.size()))
    return n < 0 ? std::strerror(errno) : "short write (" + std::to_string(n) + " bytes)";
  if (::fdatasync(fd) != 0) return std::string("fdatasync: ") + std::strerror(errno);
  return "";
}

}  // namespace eol::db
