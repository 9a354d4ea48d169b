// Stable LSD radix sort of (uint32 key, uint32 value) pairs: bindings and parameters shared by C++ and GLSL.
// Each pass sorts on one digit of up to RADIX_DIGIT_BITS bits: radix_histogram counts digits per block,
// an exclusive scan over the digit-major count table gives every (digit, block) its first destination, and
// radix_scatter moves each block's pairs there in input order (so the sort is stable).
#ifndef LITGS_KERNELS_RADIX_SORT_SHARED_H
#define LITGS_KERNELS_RADIX_SORT_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

#define RADIX_DIGIT_BITS 8
#define RADIX_BUCKETS 256  // 1 << RADIX_DIGIT_BITS

// radix_histogram.comp
#define RADIX_HISTOGRAM_BINDING_KEYS 0    // [count] read
#define RADIX_HISTOGRAM_BINDING_COUNTS 1  // [RADIX_BUCKETS][block_count] written, digit-major
#define RADIX_HISTOGRAM_BINDING_COUNT 2

// radix_scatter.comp
#define RADIX_SCATTER_BINDING_KEYS_IN 0     // [count] read
#define RADIX_SCATTER_BINDING_VALUES_IN 1   // [count] read
#define RADIX_SCATTER_BINDING_OFFSETS 2     // [RADIX_BUCKETS][block_count] read: scanned counts
#define RADIX_SCATTER_BINDING_KEYS_OUT 3    // [count] written
#define RADIX_SCATTER_BINDING_VALUES_OUT 4  // [count] written
#define RADIX_SCATTER_BINDING_COUNT 5

struct RadixPassParams {
  uint count;        // pairs to sort
  uint block_size;   // pairs per workgroup, a multiple of the subgroup size
  uint block_count;  // workgroups: ceil(count / block_size)
  uint shift;        // this pass sorts on key bits [shift, shift + digit_bits)
  uint digit_bits;   // 1 .. RADIX_DIGIT_BITS
};

#ifdef __cplusplus
static_assert(sizeof(RadixPassParams) <= 128);
static_assert(RADIX_HISTOGRAM_BINDING_COUNT == RADIX_HISTOGRAM_BINDING_COUNTS + 1);
static_assert(RADIX_SCATTER_BINDING_COUNT == RADIX_SCATTER_BINDING_VALUES_OUT + 1);
}  // namespace litgs::kernels
#endif
#endif
