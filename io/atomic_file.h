// Writing without losing what is already there: write to a temporary name beside the target, then rename.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>

namespace litgs::io {

// A temporary path beside `target` ("<target>.tmp-<pid>-<n>"); commit() renames it onto the target (atomic on
// one file system). Destroyed without commit() (an exception while writing), it removes the temporary, so the
// old target, if any, is untouched.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  void commit();  // throws IoError naming the target if the rename fails

 private:
  std::filesystem::path target_, temp_;
  bool committed_ = false;
};

// Writes a text or binary file atomically through an ostream; IoError if the stream fails.
void write_file_atomic(const std::filesystem::path& target, const std::function<void(std::ostream&)>& write);

}  // namespace litgs::io
