// Building kernels from the embedded shaders: plain ones, and ones that run one subgroup per workgroup
// (kernels/common.glsl).
#pragma once

#include <memory>
#include <string>

#include "engine/context.h"
#include "engine/kernel.h"

namespace litgs::kernels {

// The subgroup size the one-subgroup kernels use on this device: its default compute subgroup size.
uint32_t subgroup_width(const engine::Context& context);

// A kernel from the embedded shader `name`, its specialization constants and the bindings it reads as texels.
std::unique_ptr<engine::Kernel> make_kernel(engine::Context& context, const std::string& name,
                                            uint32_t binding_count, uint32_t push_constant_bytes,
                                            std::vector<engine::SpecConstant> spec_constants = {},
                                            std::vector<engine::TexelBinding> texel_bindings = {});

// A kernel from the embedded shader `name` with SUBGROUP_SIZE (constant_id 0) set and the subgroup size
// pinned, so that a workgroup is exactly one full subgroup.
std::unique_ptr<engine::Kernel> make_subgroup_kernel(engine::Context& context, const std::string& name,
                                                     uint32_t binding_count, uint32_t push_constant_bytes);

}  // namespace litgs::kernels
