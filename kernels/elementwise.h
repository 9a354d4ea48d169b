// Element-wise kernels: one invocation per element (per Gaussian, per intersection, per pixel), in
// workgroups of ELEMENTWISE_GROUP_SIZE invocations (kernels/limits.h). The host dispatches the grid that
// elementwise_groups() returns; the shader includes kernels/elementwise.glsl, takes its element from
// elementwise_index() and returns when that is >= its count.
#pragma once

#include <cstdint>

#include "engine/context.h"
#include "engine/sequence.h"

namespace litgs::kernels {

// The grid for `count` elements: one row of ceil(count / ELEMENTWISE_GROUP_SIZE) groups while that is at
// most 65535 (the x count every device allows), else the fewest rows of at most 65535 groups each. Throws
// std::length_error naming `who`, the count and the limit when the grid exceeds the device's
// maxComputeWorkGroupCount or would give an invocation an element index beyond 32 bits.
engine::Groups elementwise_groups(const engine::Context& context, uint64_t count, const char* who);

}  // namespace litgs::kernels
