// Shared by the libFuzzer targets: the readers take paths, so each input is written to a file in a
// per-process temporary directory (removed at exit) and the reader is called on it. io::IoError is the
// expected outcome for most inputs; any other exception escapes LLVMFuzzerTestOneInput, terminates the
// process and is reported by libFuzzer as a finding (as are crashes and sanitizer reports).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "io/error.h"

namespace litgs::fuzz {

// This process's scratch directory, created on first use and removed when the process exits normally:
// $LITGS_FUZZ_SCRATCH where set (ci/fuzz sets one per target, so that the paths the readers see, and with
// them the fuzzer's run, do not change with the process id), else one named by the process id.
inline const std::filesystem::path& temp_dir() {
  static const std::filesystem::path dir = [] {
    const char* fixed = std::getenv("LITGS_FUZZ_SCRATCH");
    auto d = fixed != nullptr && *fixed != '\0'
                 ? std::filesystem::path(fixed)
                 : std::filesystem::temp_directory_path() / ("litgs-fuzz-" + std::to_string(::getpid()));
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(temp_dir(), ec);
    });
    return d;
  }();
  return dir;
}

// Writes `size` bytes to temp_dir()/name (overwriting) and returns the path.
inline std::filesystem::path write_temp(const std::string& name, const uint8_t* data, size_t size) {
  const auto path = temp_dir() / name;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) std::abort();  // the harness itself failed: not a parser finding, but never silently skipped
  return path;
}

inline std::filesystem::path write_temp(const std::string& name, std::string_view bytes) {
  return write_temp(name, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

// Runs `f`, swallowing io::IoError (the documented failure of every reader); anything else propagates.
template <class F>
int expect_only_io_error(F&& f) {
  try {
    f();
  } catch (const io::IoError&) {
  }
  return 0;
}

}  // namespace litgs::fuzz
