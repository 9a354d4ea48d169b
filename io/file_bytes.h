// Whole-file reads for the binary parsers (internal to io/).
#pragma once

#include <filesystem>
#include <string>

namespace litgs::io {

// The file's bytes; IoError if it is missing or unreadable.
std::string read_file_bytes(const std::filesystem::path& path);

}  // namespace litgs::io
