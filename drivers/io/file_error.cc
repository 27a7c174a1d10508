#include "drivers/io/file_error.h"

namespace eol::io {
namespace {

std::string Where(const std::string& file, std::size_t line, std::size_t column) {
  std::string w = file;
  if (line > 0) w += ":" + std::to_string(line);
  if (line > 0 && column > 0) w += ":" + std::to_string(column);
  return w;
}

}  // namespace

FileError::FileError(const std::string& file, std::size_t line, std::size_t column,
                     const std::string& message)
    : std::runtime_error(Where(file, line, column) + ": " + message),
      file_(file),
      line_(line),
      column_(column),
      message_(message) {}

}  // namespace eol::io
