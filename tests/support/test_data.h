// The real test data shipped in tests/data (see tests/data/README.md). CMake passes its location as
// LITGS_TEST_DATA_DIR (cache variable of the same name). A test that needs a file fails, never skips, when
// the file is missing, and the message names the path: a test that silently passes without its input would
// hide a broken checkout or a wrong -DLITGS_TEST_DATA_DIR.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace litgs::testing {

// The data folder itself; throws when it is not a directory.
inline std::filesystem::path test_data_dir() {
  const std::filesystem::path dir = LITGS_TEST_DATA_DIR;
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error("test data folder missing: " + dir.string() +
                             " (tests/data in the source tree, or -DLITGS_TEST_DATA_DIR=...)");
  return dir;
}

// A file or folder under it, e.g. test_data("gsplat-garden/test_garden.npz"); throws when it does not exist.
inline std::filesystem::path test_data(const std::string& relative) {
  const std::filesystem::path path = test_data_dir() / relative;
  if (!std::filesystem::exists(path))
    throw std::runtime_error("test data missing: " + path.string() + " (listed in tests/data/README.md)");
  return path;
}

}  // namespace litgs::testing
