// drivers/io/text_table.h: CSVs as spreadsheets write them. A UTF-8 byte-order mark is
// accepted; ';' separators are refused naming the separator (issue 14: a BOM was refused).
#include <gtest/gtest.h>

#include <fstream>

#include "drivers/io/file_error.h"
#include "drivers/io/text_table.h"
#include "tests/support/child_process.h"

namespace eol::io {
namespace {

std::string Write(const eol::testing::TempDir& dir, const std::string& text) {
  const std::string path = dir / "frf.csv";
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(CsvReader, AcceptsAUtf8ByteOrderMarkBeforeTheHeader) {
  eol::testing::TempDir dir;
  const std::string path = Write(dir,
                                 "\xEF\xBB\xBF"
                                 "f_hz,re_ohm,im_ohm\r\n10,1.5,-0.25\r\n");
  const CsvTable t = ReadCsvTable(path);
  ASSERT_EQ(t.names.size(), 3u);
  EXPECT_EQ(t.names[0], "f_hz");
  EXPECT_EQ(t.Column("f_hz").at(0), 10.0);
  EXPECT_EQ(ReadCsvHeader(path).at(0), "f_hz");
}

TEST(CsvReader, RefusesSemicolonSeparatorsByName) {
  eol::testing::TempDir dir;
  const std::string path = Write(dir,
                                 "\xEF\xBB\xBF"
                                 "f_hz;re_ohm;im_ohm\n10;1,5;-0,25\n");
  for (auto read : {+[](const std::string& p) { ReadCsvTable(p); },
                    +[](const std::string& p) { ReadCsvHeader(p); }}) {
    try {
      read(path);
      ADD_FAILURE() << "a ';' CSV was read";
    } catch (const FileError& e) {
      EXPECT_EQ(e.message(),
                "columns are separated by ';'; this reader takes ',' with '.' decimals (export "
                "the CSV with a comma separator)");
      EXPECT_EQ(e.line(), 1u);
      EXPECT_EQ(e.column(), 5u);
    }
  }
}

}  // namespace
}  // namespace eol::io
