// Content hashes of a stage's inputs and outputs, to tell whether a stage must run again. A 64-bit hash
// (not cryptographic: it detects changes, it does not resist forgery). A directory's hash covers every
// regular file under it: relative path, size and content, in sorted order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace litgs::host::run {

// 16 hex digits. io::IoError naming the path when it does not exist or cannot be read.
std::string hash_path(const std::filesystem::path& path);
std::string hash_text(std::string_view text);

}  // namespace litgs::host::run
