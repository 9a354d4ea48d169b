#include "kernels/subgroup_kernel.h"

#include <stdexcept>

#include "kernels/spirv_registry.h"

namespace litgs::kernels {

uint32_t subgroup_width(const engine::Context& context) {
  const uint32_t s = context.info().subgroup_size;
  if (s == 0 || s > 128 || (s & (s - 1)) != 0)
    throw std::runtime_error("device " + context.info().name + " reports subgroup size " + std::to_string(s) +
                             "; the kernels need a power of two up to 128");
  return s;
}

namespace {
engine::KernelDesc kernel_desc(const std::string& name, uint32_t binding_count,
                               uint32_t push_constant_bytes) {
  engine::KernelDesc desc;
  desc.name = name;
  desc.spirv = spirv(name);
  desc.binding_count = binding_count;
  desc.push_constant_bytes = push_constant_bytes;
  return desc;
}
}  // namespace

std::unique_ptr<engine::Kernel> make_kernel(engine::Context& context, const std::string& name,
                                            uint32_t binding_count, uint32_t push_constant_bytes,
                                            std::vector<engine::SpecConstant> spec_constants,
                                            std::vector<engine::TexelBinding> texel_bindings) {
  engine::KernelDesc desc = kernel_desc(name, binding_count, push_constant_bytes);
  desc.spec_constants = std::move(spec_constants);
  desc.texel_bindings = std::move(texel_bindings);
  return std::make_unique<engine::Kernel>(context, std::move(desc));
}

std::unique_ptr<engine::Kernel> make_subgroup_kernel(engine::Context& context, const std::string& name,
                                                     uint32_t binding_count, uint32_t push_constant_bytes) {
  engine::KernelDesc desc = kernel_desc(name, binding_count, push_constant_bytes);
  const uint32_t width = subgroup_width(context);
  desc.spec_constants = {{0, width}};
  desc.required_subgroup_size = width;
  return std::make_unique<engine::Kernel>(context, std::move(desc));
}

}  // namespace litgs::kernels
