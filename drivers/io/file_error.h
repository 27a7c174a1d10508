// The error every file reader and writer of drivers/io throws: it names the file and,
// for text files, the line and column (1-based) where the problem is.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace eol::io {

class FileError : public std::runtime_error {
 public:
  // what() is "<file>:<line>:<column>: <message>", "<file>:<line>: <message>" when column is
  // 0, "<file>: <message>" when line is 0 too.
  FileError(const std::string& file, std::size_t line, std::size_t column,
            const std::string& message);

  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }
  std::size_t column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  std::size_t line_ = 0;
  std::size_t column_ = 0;
  std::string message_;
};

}  // namespace eol::io
