#include "host/run/content_hash.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <vector>

#include "io/error.h"

namespace litgs::host::run {
namespace {

// A word-at-a-time multiply-xorshift hash: several times the speed of FNV-1a's byte loop, which matters for
// multi-gigabyte bags hashed on every rerun (docs/experiments.md, "Figures moved out of code comments").
class Hasher {
 public:
  void add(const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    size_t i = 0;
    for (; i + 8 <= size; i += 8) {
      uint64_t w;
      std::memcpy(&w, p + i, 8);
      mix(w);
    }
    uint64_t tail = 0;
    if (size > i) std::memcpy(&tail, p + i, size - i);
    mix(tail ^ (uint64_t{size - i} << 56));
    length_ += size;
  }
  void add(std::string_view s) { add(s.data(), s.size()); }
  uint64_t finish() const {
    uint64_t h = state_ ^ length_;
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    return h ^ (h >> 33);
  }

 private:
  void mix(uint64_t w) {
    state_ ^= w * 0x9e3779b97f4a7c15ULL;
    state_ = ((state_ << 27) | (state_ >> 37)) * 0x100000001b3ULL + 0x7f4a7c15ULL;
  }
  uint64_t state_ = 0xcbf29ce484222325ULL, length_ = 0;
};

void add_file(Hasher& h, const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io::IoError(path, 0, "cannot open for hashing");
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    h.add(buffer.data(), static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) throw io::IoError(path, 0, "read error while hashing");
}

std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

std::string hash_path(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw io::IoError(path, 0, "does not exist (a stage input or output)");
  Hasher h;
  if (fs::is_regular_file(status)) {
    add_file(h, path);
    return hex(h.finish());
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(path))
    if (entry.is_regular_file()) files.push_back(fs::relative(entry.path(), path));
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    h.add(f.generic_string());
    const uint64_t size = fs::file_size(path / f);
    h.add(&size, sizeof size);
    add_file(h, path / f);
  }
  return hex(h.finish());
}

std::string hash_text(std::string_view text) {
  Hasher h;
  h.add(text);
  return hex(h.finish());
}

}  // namespace litgs::host::run
