#include "drivers/io/text_table.h"

#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>

namespace eol::io {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool Skippable(const std::string& line) {
  const std::string_view t = Trim(line);
  return t.empty() || t.front() == '#';
}

// Splits on commas; *starts receives each field's 1-based character column (after padding).
std::vector<std::string_view> SplitCsv(std::string_view line, std::vector<std::uint32_t>* starts) {
  std::vector<std::string_view> fields;
  starts->clear();
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
    std::string_view raw = line.substr(begin, end - begin);
    std::size_t lead = 0;
    while (lead < raw.size() && (raw[lead] == ' ' || raw[lead] == '\t')) ++lead;
    fields.push_back(Trim(raw));
    starts->push_back(static_cast<std::uint32_t>(begin + lead + 1));
    if (comma == std::string_view::npos) break;
    begin = comma + 1;
  }
  return fields;
}

}  // namespace

LineReader::LineReader(const std::string& path) : path_(path) {
  errno = 0;
  gz_ = gzopen(path.c_str(), "rb");
  if (!gz_)
    throw FileError(
        path, 0, 0,
        std::string("cannot open: ") + (errno ? std::strerror(errno) : "out of memory"));
}

LineReader::~LineReader() {
  if (gz_) gzclose(static_cast<gzFile>(gz_));
}

bool LineReader::Next(std::string* line) {
  line->clear();
  char buf[8192];
  bool any = false;
  while (gzgets(static_cast<gzFile>(gz_), buf, sizeof buf) != nullptr) {
    any = true;
    line->append(buf);
    if (!line->empty() && line->back() == '\n') break;
  }
  int err = Z_OK;
  const char* msg = gzerror(static_cast<gzFile>(gz_), &err);
  if (err != Z_OK && err != Z_STREAM_END)
    throw FileError(path_, line_number_ + 1, 0, std::string("read error: ") + msg);
  if (!any) return false;
  if (!line->empty() && line->back() == '\n') line->pop_back();
  if (!line->empty() && line->back() == '\r') line->pop_back();
  // A UTF-8 byte-order mark (spreadsheets write one) is not part of the first line.
  if (line_number_ == 0 && line->rfind("\xEF\xBB\xBF", 0) == 0) line->erase(0, 3);
  ++line_number_;
  return true;
}

double ParseNumber(std::string_view field, const std::string& path, std::size_t line,
                   std::size_t column, const std::string& what) {
  if (field.empty()) throw FileError(path, line, column, what + ": empty field");
  std::string_view s = field;
  if (s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec == std::errc::result_out_of_range)
    throw FileError(path, line, column, what + ": \"" + std::string(field) + "\" is out of range");
  if (ec != std::errc() || end != s.data() + s.size())
    throw FileError(path, line, column, what + ": \"" + std::string(field) + "\" is not a number");
  if (!std::isfinite(v))
    throw FileError(path, line, column,
                    what + ": \"" + std::string(field) + "\" is not a finite number");
  return v;
}

std::size_t CsvTable::Find(std::string_view name) const {
  for (std::size_t c = 0; c < names.size(); ++c)
    if (names[c] == name) return c;
  return std::string::npos;
}

const std::vector<double>& CsvTable::Column(std::string_view name) const {
  const std::size_t c = Find(name);
  if (c == std::string::npos) {
    std::string have;
    for (const auto& n : names) have += (have.empty() ? "" : ",") + n;
    throw FileError(path, 1, 0,
                    "missing column \"" + std::string(name) + "\" (header: " + have + ")");
  }
  return columns[c];
}

FileError CsvTable::ErrorAt(std::size_t row, std::size_t column_index,
                            const std::string& message) const {
  return FileError(path, row_line.at(row), field_column.at(row * names.size() + column_index),
                   names.at(column_index) + ": " + message);
}

namespace {

// A header separated by ';' (a spreadsheet in a decimal-comma locale) is refused by name:
// reading it as ',' would split "1,5" into two numbers.
void RefuseSemicolons(const std::string& path, std::size_t line_number, const std::string& line) {
  const std::size_t semi = line.find(';');
  if (semi != std::string::npos && line.find(',') == std::string::npos)
    throw FileError(path, line_number, semi + 1,
                    "columns are separated by ';'; this reader takes ',' with '.' decimals "
                    "(export the CSV with a comma separator)");
}

}  // namespace

std::vector<std::string> ReadCsvHeader(const std::string& path) {
  LineReader in(path);
  std::string line;
  std::vector<std::uint32_t> starts;
  while (in.Next(&line)) {
    if (Skippable(line)) continue;
    RefuseSemicolons(path, in.line_number(), line);
    std::vector<std::string> names;
    for (std::string_view f : SplitCsv(line, &starts)) names.emplace_back(f);
    return names;
  }
  throw FileError(path, 0, 0, "file is empty (no header line)");
}

CsvTable ReadCsvTable(const std::string& path) {
  LineReader in(path);
  CsvTable t;
  t.path = path;
  std::string line;
  std::vector<std::uint32_t> starts;
  bool header = false;
  while (in.Next(&line)) {
    if (Skippable(line)) continue;
    const std::vector<std::string_view> fields = SplitCsv(line, &starts);
    const std::size_t ln = in.line_number();
    if (!header) {
      RefuseSemicolons(path, ln, line);
      for (std::size_t c = 0; c < fields.size(); ++c) {
        if (fields[c].empty())
          throw FileError(path, ln, starts[c], "empty column name in the header");
        for (std::size_t d = 0; d < c; ++d)
          if (fields[d] == fields[c])
            throw FileError(
                path, ln, starts[c],
                "column \"" + std::string(fields[c]) + "\" appears twice in the header");
        t.names.emplace_back(fields[c]);
      }
      t.columns.resize(t.names.size());
      header = true;
      continue;
    }
    if (fields.size() != t.names.size()) {
      const std::size_t col = fields.size() > t.names.size()
                                  ? starts[t.names.size()]
                                  : static_cast<std::size_t>(line.size() + 1);
      throw FileError(path, ln, col,
                      "expected " + std::to_string(t.names.size()) + " fields, found " +
                          std::to_string(fields.size()));
    }
    for (std::size_t c = 0; c < fields.size(); ++c) {
      t.columns[c].push_back(ParseNumber(fields[c], path, ln, starts[c], t.names[c]));
      t.field_column.push_back(starts[c]);
    }
    t.row_line.push_back(ln);
  }
  if (!header) throw FileError(path, 0, 0, "file is empty (no header line)");
  if (t.rows() == 0) throw FileError(path, in.line_number(), 0, "no data rows after the header");
  return t;
}

}  // namespace eol::io
