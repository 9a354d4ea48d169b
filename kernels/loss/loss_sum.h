// The deterministic two-column sum shared by the loss kernels (reduce_blocks + reduce_finish): rows of two
// floats summed in a fixed order, then a linear map of the two sums written to a loss buffer's slots.
// Internal to kernels/loss/.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/kernel.h"
#include "engine/sequence.h"
#include "kernels/loss/loss_shared.h"
#include "kernels/subgroup_kernel.h"

namespace litgs::kernels::loss_detail {

// Throws std::invalid_argument naming `who`, `what` and the sizes when `buffer` holds fewer than `bytes`.
void check_binding(const char* who, const char* what, const engine::Buffer& buffer, uint64_t bytes);

using kernels::make_kernel;  // kernels/subgroup_kernel.h

class LossSum {
 public:
  explicit LossSum(engine::Context& context);
  // Scratch for sums of up to `rows` rows.
  void reserve(uint64_t rows);
  // Records the sum of `rows` rows of `terms` ([rows][2] float) and writes `params.outputs` values from
  // `params.slot` of `out` (params.count and the slot are checked here; count is set here).
  void record(engine::Sequence& sequence, const engine::Buffer& terms, uint64_t rows, ReduceParams params,
              const engine::Buffer& out);

 private:
  engine::Context* context_;
  std::unique_ptr<engine::Kernel> blocks_, finish_;
  std::unique_ptr<engine::DeviceArray<float>> block_sums_;  // [blocks][2]
};

}  // namespace litgs::kernels::loss_detail
