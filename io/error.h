// The one exception type of io/: a file (and where known a line or byte offset) plus the problem.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace litgs::io {

// Bad input at a file boundary. what() reads "FILE:LINE: PROBLEM" (or "FILE: PROBLEM" where no line applies,
// "FILE: byte N: PROBLEM" for binary data), so a user can open the file at the place that is wrong.
class IoError : public std::runtime_error {
 public:
  IoError(std::filesystem::path file, int64_t line, const std::string& problem);
  const std::filesystem::path& file() const { return file_; }
  int64_t line() const { return line_; }  // 1-based; 0 when the problem has no line

 private:
  std::filesystem::path file_;
  int64_t line_;
};

// Throws IoError(file, line, problem). line 0: no line.
[[noreturn]] void fail(const std::filesystem::path& file, int64_t line, const std::string& problem);

// Throws IoError for binary data: "FILE: byte OFFSET: PROBLEM".
[[noreturn]] void fail_at_byte(const std::filesystem::path& file, uint64_t offset,
                               const std::string& problem);

}  // namespace litgs::io
