#include "io/error.h"

namespace litgs::io {
namespace {

std::string format(const std::filesystem::path& file, int64_t line, const std::string& problem) {
  return line > 0 ? file.string() + ":" + std::to_string(line) + ": " + problem
                  : file.string() + ": " + problem;
}

}  // namespace

IoError::IoError(std::filesystem::path file, int64_t line, const std::string& problem)
    : std::runtime_error(format(file, line, problem)), file_(std::move(file)), line_(line) {}

void fail(const std::filesystem::path& file, int64_t line, const std::string& problem) {
  throw IoError(file, line, problem);
}

void fail_at_byte(const std::filesystem::path& file, uint64_t offset, const std::string& problem) {
  throw IoError(file, 0, "byte " + std::to_string(offset) + ": " + problem);
}

}  // namespace litgs::io
