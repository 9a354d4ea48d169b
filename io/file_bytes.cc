#include "io/file_bytes.h"

#include <fstream>
#include <iterator>

#include "io/error.h"

namespace litgs::io {

std::string read_file_bytes(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) fail(path, 0, "file does not exist");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, 0, "cannot open for reading");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail(path, 0, "read error");
  return bytes;
}

}  // namespace litgs::io
