// Exclusive prefix sum of uint32 on the device (sums wrap modulo 2^32), in place.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"

namespace litgs::kernels {

struct ScanOptions {
  // Elements per workgroup; a multiple of the subgroup size. 0: 256 subgroup-wide batches on a CPU device,
  // 32 on a GPU.
  uint32_t block_size = 0;
  // Throws std::invalid_argument naming the bad field.
  void check(uint32_t subgroup_size) const;
};

class ExclusiveScan {
 public:
  explicit ExclusiveScan(engine::Context& context, ScanOptions options = {});
  ~ExclusiveScan();

  // Records the scan of data[0 .. count) in place. Scratch grows on demand (allocated while recording).
  void record(engine::Sequence& sequence, const engine::Buffer& data, uint32_t count);

  uint32_t block_size() const { return block_size_; }
  // Levels of block sums a scan of `count` elements uses (0 when one block holds it all).
  uint32_t levels(uint32_t count) const;

 private:
  void record_level(engine::Sequence& sequence, const engine::Buffer& data, uint32_t count, size_t level);

  engine::Context* context_;
  uint32_t block_size_;
  std::unique_ptr<engine::Kernel> reduce_;
  std::unique_ptr<engine::Kernel> downsweep_;
  std::vector<std::unique_ptr<engine::DeviceArray<uint32_t>>> block_sums_;  // [levels], stable addresses
  std::vector<std::unique_ptr<engine::DeviceArray<uint32_t>>>
      retired_;                                   // outgrown, kept for recorded sequences
  engine::DeviceArray<uint32_t> unused_offsets_;  // bound where a kernel ignores its offsets
};

}  // namespace litgs::kernels
