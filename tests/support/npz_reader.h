// Reads NumPy .npz archives (a zip of .npy arrays), little-endian float32/uint8/int64, C order only.
// Test support for the gsplat garden data; errors name the archive, the array and the problem.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace litgs::testing {

struct NpyArray {
  std::string dtype;           // numpy descr, e.g. "<f4", "|u1", "<i8"
  std::vector<size_t> shape;   // () for a scalar
  std::vector<uint8_t> bytes;  // raw little-endian data
  size_t element_count() const;
  std::vector<float> as_float() const;  // from <f4, <f8, |u1 or <i8
  int64_t as_scalar_int() const;        // a () or (1,) integer array
};

// Throws std::runtime_error naming the file and array when missing, truncated or of an unsupported kind.
NpyArray read_npz_array(const std::string& npz_path, const std::string& name);

}  // namespace litgs::testing
