#include "kernels/scan/scan.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "kernels/device_growth.h"
#include "kernels/limits.h"
#include "kernels/scan/scan_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

using engine::Access;

void ScanOptions::check(uint32_t subgroup_size) const {
  if (block_size != 0 && (block_size % subgroup_size != 0))
    throw std::invalid_argument("ScanOptions.block_size = " + std::to_string(block_size) +
                                " must be 0 or a multiple of the subgroup size " +
                                std::to_string(subgroup_size));
  if (block_size / subgroup_size > MAX_BATCHES_PER_WORKGROUP)
    throw std::invalid_argument("ScanOptions.block_size = " + std::to_string(block_size) + " exceeds " +
                                std::to_string(MAX_BATCHES_PER_WORKGROUP) +
                                " subgroup-wide batches per workgroup");
}

ExclusiveScan::ExclusiveScan(engine::Context& context, ScanOptions options)
    : context_(&context), unused_offsets_(context, "scan: unused offsets", 1) {
  const uint32_t width = subgroup_width(context);
  options.check(width);
  // A block is walked serially by one subgroup. A CPU device runs each workgroup on one thread, so long
  // blocks (few dispatches) suit it; a GPU waits on each batch's load in turn, so it takes shorter blocks
  // and many more workgroups (on an H200, 32 batches instead of 256 made the scans several times faster:
  // docs/experiments.md, "the first runs on a real GPU", issue 18).
  const uint32_t batches = context.info().type == "cpu" ? 256u : 32u;
  block_size_ = options.block_size != 0 ? options.block_size : width * batches;
  reduce_ = make_subgroup_kernel(context, "scan/scan_reduce", SCAN_REDUCE_BINDING_COUNT, sizeof(ScanParams));
  downsweep_ =
      make_subgroup_kernel(context, "scan/scan_downsweep", SCAN_DOWNSWEEP_BINDING_COUNT, sizeof(ScanParams));
}

ExclusiveScan::~ExclusiveScan() = default;

uint32_t ExclusiveScan::levels(uint32_t count) const {
  uint32_t levels = 0;
  for (uint64_t n = count; n > block_size_; n = (n + block_size_ - 1) / block_size_) ++levels;
  return levels;
}

void ExclusiveScan::record(engine::Sequence& sequence, const engine::Buffer& data, uint32_t count) {
  if (static_cast<uint64_t>(count) * sizeof(uint32_t) > data.size_bytes())
    throw std::out_of_range("scan of " + std::to_string(count) + " elements but buffer '" + data.name() +
                            "' holds " + std::to_string(data.size_bytes() / sizeof(uint32_t)));
  if (count == 0) return;
  record_level(sequence, data, count, 0);
}

void ExclusiveScan::record_level(engine::Sequence& sequence, const engine::Buffer& data, uint32_t count,
                                 size_t level) {
  const uint32_t blocks = (count + block_size_ - 1) / block_size_;
  ScanParams params{count, block_size_, 0u, 0u};
  if (blocks == 1) {
    sequence.dispatch(*downsweep_, {1},
                      {{SCAN_DOWNSWEEP_BINDING_DATA, &data, Access::kReadWrite},
                       {SCAN_DOWNSWEEP_BINDING_BLOCK_OFFSETS, &unused_offsets_.buffer(), Access::kRead}},
                      params);
    return;
  }
  if (block_sums_.size() <= level) block_sums_.resize(level + 1);
  std::unique_ptr<engine::DeviceArray<uint32_t>>& level_sums = block_sums_[level];
  // A sequence recorded earlier may still use an outgrown buffer, so it is retired (kept alive).
  if (!level_sums || level_sums->size() < blocks)
    grow(*context_, level_sums, blocks, "scan: block sums level " + std::to_string(level), &retired_);
  // Owned through a unique_ptr: the deeper levels below may grow block_sums_ without moving this buffer.
  const engine::Buffer& sums = level_sums->buffer();
  sequence.dispatch(*reduce_, {blocks},
                    {{SCAN_REDUCE_BINDING_DATA, &data, Access::kRead},
                     {SCAN_REDUCE_BINDING_BLOCK_SUMS, &sums, Access::kWrite}},
                    params);
  record_level(sequence, sums, blocks, level + 1);
  params.use_block_offsets = 1u;
  sequence.dispatch(*downsweep_, {blocks},
                    {{SCAN_DOWNSWEEP_BINDING_DATA, &data, Access::kReadWrite},
                     {SCAN_DOWNSWEEP_BINDING_BLOCK_OFFSETS, &sums, Access::kRead}},
                    params);
}

}  // namespace litgs::kernels
