// Exclusive scan of uint32 (sums wrap modulo 2^32): bindings and parameters shared by C++ and GLSL.
// The scan is block-wise: scan_reduce sums each block of `block_size` elements, the block sums are scanned
// (recursively, by the same two kernels), and scan_downsweep scans each block in place from its offset.
#ifndef LITGS_KERNELS_SCAN_SHARED_H
#define LITGS_KERNELS_SCAN_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace litgs::kernels {
using uint = uint32_t;
#endif

// scan_reduce.comp
#define SCAN_REDUCE_BINDING_DATA 0        // [count] read
#define SCAN_REDUCE_BINDING_BLOCK_SUMS 1  // [block_count] written: sum of each block
#define SCAN_REDUCE_BINDING_COUNT 2

// scan_downsweep.comp
#define SCAN_DOWNSWEEP_BINDING_DATA 0           // [count] scanned in place
#define SCAN_DOWNSWEEP_BINDING_BLOCK_OFFSETS 1  // [block_count] read when use_block_offsets != 0
#define SCAN_DOWNSWEEP_BINDING_COUNT 2

struct ScanParams {
  uint count;              // elements to scan
  uint block_size;         // elements per workgroup, a multiple of the subgroup size
  uint use_block_offsets;  // downsweep: 1 adds block_offsets[block], 0 starts every block at 0
  uint reserved;
};

#ifdef __cplusplus
static_assert(sizeof(ScanParams) <= 128);
static_assert(SCAN_REDUCE_BINDING_COUNT == SCAN_REDUCE_BINDING_BLOCK_SUMS + 1);
static_assert(SCAN_DOWNSWEEP_BINDING_COUNT == SCAN_DOWNSWEEP_BINDING_BLOCK_OFFSETS + 1);
}  // namespace litgs::kernels
#endif
#endif
