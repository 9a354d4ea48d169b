#include "kernels/elementwise.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "kernels/limits.h"

namespace litgs::kernels {

engine::Groups elementwise_groups(const engine::Context& context, uint64_t count, const char* who) {
  // 65535 groups in x is what Vulkan guarantees; beyond it the grid gets rows, and the rows are balanced
  // (x = ceil(groups / rows)) so that at most rows - 1 groups lie past the last element.
  constexpr uint64_t kRowGroups = 65535;
  const uint64_t groups = (count + ELEMENTWISE_GROUP_SIZE - 1) / ELEMENTWISE_GROUP_SIZE;
  const uint64_t y = std::max<uint64_t>(1, (groups + kRowGroups - 1) / kRowGroups);
  const uint64_t x = (groups + y - 1) / y;
  const uint32_t* limit = context.info().max_compute_workgroup_count;
  // elementwise_index() is a uint: an invocation past 2^32 would wrap onto an element of the first row.
  if (x > limit[0] || y > limit[1] || x * y * ELEMENTWISE_GROUP_SIZE > (uint64_t{1} << 32))
    throw std::length_error(std::string(who) + ": " + std::to_string(count) + " elements need a grid of " +
                            std::to_string(x) + " x " + std::to_string(y) + " workgroups of " +
                            std::to_string(ELEMENTWISE_GROUP_SIZE) + "; the device allows " +
                            std::to_string(limit[0]) + " x " + std::to_string(limit[1]) +
                            " and the element index at most 2^32 invocations");
  return {static_cast<uint32_t>(x), static_cast<uint32_t>(y), 1};
}

}  // namespace litgs::kernels
