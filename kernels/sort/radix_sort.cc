#include "kernels/sort/radix_sort.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "kernels/device_growth.h"
#include "kernels/limits.h"
#include "kernels/sort/radix_sort_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels {

using engine::Access;

void RadixSortOptions::check() const {
  if (min_batches_per_block == 0)
    throw std::invalid_argument("RadixSortOptions.min_batches_per_block must be at least 1");
  if (max_blocks > 65535)
    throw std::invalid_argument("RadixSortOptions.max_blocks = " + std::to_string(max_blocks) +
                                " exceeds 65535, the smallest maxComputeWorkGroupCount Vulkan allows");
}

RadixSort::RadixSort(engine::Context& context, RadixSortOptions options)
    : context_(&context), options_(options), width_(subgroup_width(context)), scan_(context) {
  options_.check();
  if (options_.max_blocks == 0) options_.max_blocks = context.info().type == "cpu" ? 64 : 2048;
  histogram_ = make_subgroup_kernel(context, "sort/radix_histogram", RADIX_HISTOGRAM_BINDING_COUNT,
                                    sizeof(RadixPassParams));
  scatter_ = make_subgroup_kernel(context, "sort/radix_scatter", RADIX_SCATTER_BINDING_COUNT,
                                  sizeof(RadixPassParams));
}

RadixSort::~RadixSort() = default;

RadixSort::Layout RadixSort::layout(uint32_t count) const {
  if (count == 0) return {width_, 0};
  const uint64_t min_block = static_cast<uint64_t>(width_) * options_.min_batches_per_block;
  const uint64_t max_block = static_cast<uint64_t>(width_) * MAX_BATCHES_PER_WORKGROUP;
  uint64_t blocks = std::clamp<uint64_t>((count + min_block - 1) / min_block, 1, options_.max_blocks);
  blocks = std::max<uint64_t>(blocks, (count + max_block - 1) / max_block);  // loop cap beats max_blocks
  uint64_t block_size = (count + blocks - 1) / blocks;
  block_size = (block_size + width_ - 1) / width_ * width_;
  blocks = (count + block_size - 1) / block_size;
  return {static_cast<uint32_t>(block_size), static_cast<uint32_t>(blocks)};
}

void RadixSort::reserve(uint32_t count, uint32_t blocks) {
  // Outgrown scratch is retired, not freed, while a recorded sequence may use it: kept alive.
  grow(*context_, keys_tmp_, count, "radix sort: keys scratch", &retired_);
  grow(*context_, values_tmp_, count, "radix sort: values scratch", &retired_);
  grow(*context_, counts_, static_cast<size_t>(RADIX_BUCKETS) * blocks, "radix sort: digit counts",
       &retired_);
}

void RadixSort::record(engine::Sequence& sequence, const engine::DeviceArray<uint32_t>& keys,
                       const engine::DeviceArray<uint32_t>& values, uint32_t count, uint32_t bits) {
  if (bits > 32) throw std::invalid_argument("radix sort: bits = " + std::to_string(bits) + ", at most 32");
  if (count > keys.size() || count > values.size())
    throw std::out_of_range("radix sort of " + std::to_string(count) + " pairs, but '" + keys.name() +
                            "' holds " + std::to_string(keys.size()) + " and '" + values.name() + "' holds " +
                            std::to_string(values.size()));
  if (count <= 1 || bits == 0) return;

  const Layout l = layout(count);
  reserve(count, l.block_count);
  const uint32_t table = RADIX_BUCKETS * l.block_count;

  const engine::Buffer* src_keys = &keys.buffer();
  const engine::Buffer* src_values = &values.buffer();
  const engine::Buffer* dst_keys = &keys_tmp_->buffer();
  const engine::Buffer* dst_values = &values_tmp_->buffer();
  const engine::Buffer& counts = counts_->buffer();
  const uint32_t passes = (bits + RADIX_DIGIT_BITS - 1) / RADIX_DIGIT_BITS;
  for (uint32_t pass = 0; pass < passes; ++pass) {
    const uint32_t shift = pass * RADIX_DIGIT_BITS;
    const RadixPassParams params{count, l.block_size, l.block_count, shift,
                                 std::min<uint32_t>(RADIX_DIGIT_BITS, bits - shift)};
    sequence.dispatch(*histogram_, {l.block_count},
                      {{RADIX_HISTOGRAM_BINDING_KEYS, src_keys, Access::kRead},
                       {RADIX_HISTOGRAM_BINDING_COUNTS, &counts, Access::kWrite}},
                      params);
    scan_.record(sequence, counts, table);
    sequence.dispatch(*scatter_, {l.block_count},
                      {{RADIX_SCATTER_BINDING_KEYS_IN, src_keys, Access::kRead},
                       {RADIX_SCATTER_BINDING_VALUES_IN, src_values, Access::kRead},
                       {RADIX_SCATTER_BINDING_OFFSETS, &counts, Access::kRead},
                       {RADIX_SCATTER_BINDING_KEYS_OUT, dst_keys, Access::kWrite},
                       {RADIX_SCATTER_BINDING_VALUES_OUT, dst_values, Access::kWrite}},
                      params);
    std::swap(src_keys, dst_keys);
    std::swap(src_values, dst_values);
  }
  if (passes % 2 == 1) {  // the result sits in the scratch buffers
    sequence.copy(*src_keys, keys.buffer(), static_cast<uint64_t>(count) * sizeof(uint32_t));
    sequence.copy(*src_values, values.buffer(), static_cast<uint64_t>(count) * sizeof(uint32_t));
  }
}

}  // namespace litgs::kernels
