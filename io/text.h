// Strict text parsing shared by the line-based formats (TUM, anchors, planes, IMU CSV, PCD/PLY headers).
// Every function that can fail names the file and line it was given.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace litgs::io {

// Reads a text file line by line, counting lines (1-based) and stripping a trailing '\r'.
class LineReader {
 public:
  explicit LineReader(std::filesystem::path path);  // throws IoError if the file cannot be opened
  bool next(std::string& line);                     // false at the end of the file
  int64_t line_number() const { return line_; }     // of the line last returned
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  int64_t line_ = 0;
};

// Splits on spaces and tabs; no empty tokens.
std::vector<std::string_view> split_ws(std::string_view s);
// Splits on one delimiter character; keeps empty tokens (so "1,,2" has three), trims spaces around each.
std::vector<std::string_view> split_char(std::string_view s, char delimiter);
// s without leading and trailing spaces, tabs and '\r'.
std::string_view trim(std::string_view s);
// True for an empty line, a line of blanks, or a comment starting with '#'.
bool is_blank_or_comment(std::string_view s);

// The whole token as a finite double; otherwise IoError naming file, line, what and the token.
double parse_double(std::string_view token, const std::filesystem::path& file, int64_t line,
                    std::string_view what);
// The whole token as an integer in [lo, hi]; otherwise IoError.
int64_t parse_int(std::string_view token, const std::filesystem::path& file, int64_t line,
                  std::string_view what, int64_t lo, int64_t hi);
// Strict parse without a location: false if the token is not entirely a finite double.
bool try_parse_double(std::string_view token, double& value);

// The shortest decimal text that reads back as exactly x (std::to_chars), for writers that must round-trip.
std::string format_double(double x);

}  // namespace litgs::io
