#include <gtest/gtest.h>

#include "io/atomic_file.h"
#include "io/text.h"
#include "tests/io/io_test.h"

namespace litgs::io {
namespace {

TEST(Text, ParseDoubleIsStrict) {
  EXPECT_EQ(parse_double("1.5", "f.txt", 3, "x"), 1.5);
  EXPECT_EQ(parse_double("+2e-3", "f.txt", 3, "x"), 2e-3);
  testing::expect_io_error([] { parse_double("1.5abc", "f.txt", 3, "x"); }, {"f.txt:3:", "x", "1.5abc"});
  testing::expect_io_error([] { parse_double("nan", "f.txt", 7, "qx"); }, {"f.txt:7:", "qx", "non-finite"});
  testing::expect_io_error([] { parse_double("inf", "f.txt", 7, "qx"); }, {"non-finite"});
  testing::expect_io_error([] { parse_double("", "f.txt", 7, "qx"); }, {"not a number"});
}

TEST(Text, FormatDoubleRoundTrips) {
  for (double x : {0.1, 1.0 / 3.0, 1628410457.030000210, -1e-300, 773.73270872853072}) {
    double y = 0;
    ASSERT_TRUE(try_parse_double(format_double(x), y));
    EXPECT_EQ(x, y);
  }
}

TEST(Text, SplitCharKeepsEmptyFields) {
  const auto f = split_char(" 1, ,2 ", ',');
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0], "1");
  EXPECT_EQ(f[1], "");
  EXPECT_EQ(f[2], "2");
}

class AtomicFileTest : public testing::TempDirTest {};

TEST_F(AtomicFileTest, FailedWriteKeepsTheOldFile) {
  const auto path = write_text("keep.txt", "old");
  EXPECT_THROW(write_file_atomic(path,
                                 [](std::ostream& out) {
                                   out << "new partial";
                                   throw std::runtime_error("writer failed");
                                 }),
               std::runtime_error);
  std::ifstream in(path);
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "old");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), {}), 1) << "temporary file left behind";
  write_file_atomic(path, [](std::ostream& out) { out << "new"; });
  std::ifstream in2(path);
  std::getline(in2, s);
  EXPECT_EQ(s, "new");
}

}  // namespace
}  // namespace litgs::io
