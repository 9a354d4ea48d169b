// Stable key-value radix sort on the device: uint32 keys, uint32 values, on the low `bits` key bits.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/scan/scan.h"

namespace litgs::kernels {

struct RadixSortOptions {
  // Most workgroups per pass. Each owns one contiguous block of pairs and one column of the count table,
  // so more blocks mean more parallelism and a larger scan. 0: 64 on CPU devices (a few per core, so the
  // driver's threads balance), 2048 on GPUs.
  uint32_t max_blocks = 0;
  // Fewest subgroup-wide batches per block, so small sorts do not spread over many near-empty blocks.
  uint32_t min_batches_per_block = 32;
  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

class RadixSort {
 public:
  explicit RadixSort(engine::Context& context, RadixSortOptions options = {});
  ~RadixSort();

  // Records a stable sort of (keys[i], values[i]), i < count, by the low `bits` bits of the key (1..32;
  // 0 records nothing), in place. Higher key bits are ignored and keep their input order among equal low
  // bits. Scratch grows on demand; a recorded sequence keeps using the scratch of this RadixSort.
  void record(engine::Sequence& sequence, const engine::DeviceArray<uint32_t>& keys,
              const engine::DeviceArray<uint32_t>& values, uint32_t count, uint32_t bits = 32);

  // The block layout a sort of `count` pairs uses (for benchmarks and tests).
  struct Layout {
    uint32_t block_size = 0;
    uint32_t block_count = 0;
  };
  Layout layout(uint32_t count) const;

 private:
  void reserve(uint32_t count, uint32_t blocks);

  engine::Context* context_;
  RadixSortOptions options_;
  uint32_t width_;
  std::unique_ptr<engine::Kernel> histogram_;
  std::unique_ptr<engine::Kernel> scatter_;
  ExclusiveScan scan_;
  std::unique_ptr<engine::DeviceArray<uint32_t>> keys_tmp_;              // [capacity]
  std::unique_ptr<engine::DeviceArray<uint32_t>> values_tmp_;            // [capacity]
  std::unique_ptr<engine::DeviceArray<uint32_t>> counts_;                // [RADIX_BUCKETS][block_count]
  std::vector<std::unique_ptr<engine::DeviceArray<uint32_t>>> retired_;  // outgrown scratch
};

}  // namespace litgs::kernels
