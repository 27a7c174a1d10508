// Line-oriented text input for the file readers: plain or gzip-compressed files alike (zlib's
// gzopen reads both), and a numeric table parser with file:line:column errors.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/io/file_error.h"

namespace eol::io {

// Reads a text file line by line, without the line end ("\n" or "\r\n") and without a UTF-8
// byte-order mark at the start of the file. Throws FileError
// when the file cannot be opened or read. Not copyable.
class LineReader {
 public:
  explicit LineReader(const std::string& path);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  // False at the end of the file.
  bool Next(std::string* line);
  std::size_t line_number() const { return line_number_; }  // of the line last returned
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  void* gz_ = nullptr;  // gzFile
  std::size_t line_number_ = 0;
};

// Parses one number (decimal or exponent notation, locale-independent). The whole field must
// be consumed and the value finite: "abc", "1.2.3", "nan" and "inf" are errors, reported by
// FileError at (line, column) with `what` naming the field.
double ParseNumber(std::string_view field, const std::string& path, std::size_t line,
                   std::size_t column, const std::string& what);

// A numeric CSV: one header line of column names, then rows of comma-separated numbers.
// Blank lines and lines starting with '#' are skipped; fields may be padded with spaces.
// A UTF-8 byte-order mark before the header is accepted (LineReader drops it); a header
// separated by ';' is refused naming the separator.
struct CsvTable {
  std::string path;
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[c][row]
  std::vector<std::size_t> row_line;         // file line of each row (1-based)
  std::vector<std::uint32_t> field_column;   // [row * names.size() + c]: 1-based character column

  std::size_t rows() const { return row_line.size(); }
  // Index of the column, or npos.
  std::size_t Find(std::string_view name) const;
  // The column; throws FileError at the header line when it is missing.
  const std::vector<double>& Column(std::string_view name) const;
  // A FileError pointing at one field.
  FileError ErrorAt(std::size_t row, std::size_t column_index, const std::string& message) const;
};

// The column names of a CSV's header line (the first line that is neither blank nor a '#'
// comment), without reading the rows. Throws FileError when the file cannot be read or is empty.
std::vector<std::string> ReadCsvHeader(const std::string& path);

// Throws FileError: cannot open, empty file, header with an empty or repeated name, a row
// with too few or too many fields, a field that is not a finite number, no data rows.
CsvTable ReadCsvTable(const std::string& path);

}  // namespace eol::io
