#include "kernels/loss/loss_sum.h"

#include <algorithm>
#include <stdexcept>

#include "kernels/device_growth.h"
#include "kernels/limits.h"
#include "kernels/spirv_registry.h"

namespace litgs::kernels::loss_detail {

void check_binding(const char* who, const char* what, const engine::Buffer& buffer, uint64_t bytes) {
  if (buffer.size_bytes() < bytes)
    throw std::invalid_argument(std::string(who) + ": " + what + " buffer '" + buffer.name() + "' holds " +
                                std::to_string(buffer.size_bytes()) + " bytes, needs " +
                                std::to_string(bytes));
  const uint64_t range = buffer.context().info().max_storage_buffer_range;
  if (range != 0 && bytes > range)
    throw std::length_error(std::string(who) + ": " + what + " needs a binding of " + std::to_string(bytes) +
                            " bytes, over the device's maxStorageBufferRange of " + std::to_string(range));
}

LossSum::LossSum(engine::Context& context) : context_(&context) {
  blocks_ = make_kernel(context, "loss/reduce_blocks", REDUCE_BLOCKS_BINDING_COUNT, sizeof(ReduceParams));
  finish_ = make_kernel(context, "loss/reduce_finish", REDUCE_FINISH_BINDING_COUNT, sizeof(ReduceParams));
}

namespace {
uint64_t block_count(uint64_t rows) {
  return std::max<uint64_t>(1, (rows + LOSS_REDUCE_ROWS_PER_GROUP - 1) / LOSS_REDUCE_ROWS_PER_GROUP);
}
}  // namespace

void LossSum::reserve(uint64_t rows) {
  grow(*context_, block_sums_, block_count(rows) * 2, "loss: block sums");
}

void LossSum::record(engine::Sequence& sequence, const engine::Buffer& terms, uint64_t rows,
                     ReduceParams params, const engine::Buffer& out) {
  if (params.outputs < 1 || params.outputs > 3)
    throw std::invalid_argument("LossSum: outputs = " + std::to_string(params.outputs) + ", must be 1..3");
  const uint64_t blocks = block_count(rows);
  // reduce_finish walks the block sums 256 at a time: stay within lavapipe's loop budget (limits.h).
  if (blocks > uint64_t{256} * MAX_BATCHES_PER_WORKGROUP || rows > 0xFFFFFFFFull)
    throw std::length_error("LossSum: " + std::to_string(rows) + " rows exceed the reduction's capacity");
  check_binding("LossSum", "terms", terms, rows * 2 * sizeof(float));
  check_binding("LossSum", "loss output", out, (uint64_t{params.slot} + params.outputs) * sizeof(float));
  reserve(rows);
  params.count = static_cast<uint32_t>(rows);
  sequence.dispatch(*blocks_, {static_cast<uint32_t>(blocks)},
                    {{REDUCE_BLOCKS_BINDING_ROWS, &terms, engine::Access::kRead},
                     {REDUCE_BLOCKS_BINDING_SUMS, &block_sums_->buffer(), engine::Access::kWrite}},
                    params);
  params.count = static_cast<uint32_t>(blocks);
  sequence.dispatch(*finish_, {1},
                    {{REDUCE_FINISH_BINDING_SUMS, &block_sums_->buffer(), engine::Access::kRead},
                     {REDUCE_FINISH_BINDING_OUT, &out, engine::Access::kReadWrite}},
                    params);
}

}  // namespace litgs::kernels::loss_detail
