// Binary scalar types shared by the PCD and PLY parsers (internal to io/).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

namespace litgs::io {

enum class ScalarType { kI8, kU8, kI16, kU16, kI32, kU32, kI64, kU64, kF32, kF64 };

inline size_t scalar_size(ScalarType t) {
  switch (t) {
    case ScalarType::kI8:
    case ScalarType::kU8:
      return 1;
    case ScalarType::kI16:
    case ScalarType::kU16:
      return 2;
    case ScalarType::kI32:
    case ScalarType::kU32:
    case ScalarType::kF32:
      return 4;
    default:
      return 8;
  }
}

// Reads one scalar at p (unaligned), stored little- or big-endian, as double.
inline double read_scalar(const unsigned char* p, ScalarType t, bool big_endian) {
  unsigned char b[8];
  const size_t n = scalar_size(t);
  for (size_t i = 0; i < n; ++i) b[i] = big_endian ? p[n - 1 - i] : p[i];  // the host is little-endian
  switch (t) {
    case ScalarType::kI8:
      return static_cast<int8_t>(b[0]);
    case ScalarType::kU8:
      return b[0];
#define LITGS_READ_AS(T)           \
  {                                \
    T v;                           \
    std::memcpy(&v, b, n);         \
    return static_cast<double>(v); \
  }
    case ScalarType::kI16:
      LITGS_READ_AS(int16_t)
    case ScalarType::kU16:
      LITGS_READ_AS(uint16_t)
    case ScalarType::kI32:
      LITGS_READ_AS(int32_t)
    case ScalarType::kU32:
      LITGS_READ_AS(uint32_t)
    case ScalarType::kI64:
      LITGS_READ_AS(int64_t)
    case ScalarType::kU64:
      LITGS_READ_AS(uint64_t)
    case ScalarType::kF32:
      LITGS_READ_AS(float)
    case ScalarType::kF64:
      LITGS_READ_AS(double)
#undef LITGS_READ_AS
  }
  return 0;
}

}  // namespace litgs::io
