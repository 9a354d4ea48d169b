// A compute kernel: a pipeline built from embedded SPIR-V, with its buffer bindings declared once (storage
// buffers, or uniform texel buffers for bindings it only reads), a typed push-constant block and
// specialization constants.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace litgs::engine {

class Context;

struct SpecConstant {
  uint32_t id = 0;     // layout(constant_id = id)
  uint32_t value = 0;  // bit pattern of the uint / int / bool / float constant
};

// A binding the kernel reads as a uniform texel buffer (GLSL `samplerBuffer` / `usamplerBuffer` with
// texelFetch) instead of a storage buffer. Why: on CPU drivers (lavapipe) a storage-buffer load at an index
// that differs per invocation is a loop over the SIMD lanes, while a texel fetch is one vector gather, and a
// four-component texel fetches 16 bytes per lane at once (`bench gather` measures it: docs/performance.md,
// docs/experiments.md "the rasterizer's per-entry reads as texel fetches", issue 18).
struct TexelBinding {
  uint32_t index = 0;                     // binding index, < KernelDesc::binding_count
  VkFormat format = VK_FORMAT_UNDEFINED;  // element format: R32_UINT, R32_SFLOAT or R32G32B32A32_SFLOAT
                                          // (uniform texel support is mandatory for them)
};

struct KernelDesc {
  std::string name;                          // for profiles and error messages, e.g. "sort/radix_scatter"
  std::span<const uint32_t> spirv;           // embedded words (kernels/spirv_registry.h)
  uint32_t binding_count = 0;                // buffers at bindings 0 .. binding_count-1 of set 0
  std::vector<TexelBinding> texel_bindings;  // those read as uniform texel buffers; the rest are storage
  uint32_t push_constant_bytes = 0;          // size of the push-constant struct, 0 if none
  std::vector<SpecConstant> spec_constants;
  // Nonzero: run the kernel with exactly this subgroup size and full subgroups (the workgroup is built
  // from whole subgroups). Needs DeviceInfo::compute_full_subgroups unless it equals the fixed size.
  uint32_t required_subgroup_size = 0;
};

class Kernel {
 public:
  // Throws std::invalid_argument naming the kernel when the description exceeds a device limit.
  Kernel(Context& context, KernelDesc desc);
  ~Kernel();
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;

  const std::string& name() const { return desc_.name; }
  uint32_t binding_count() const { return desc_.binding_count; }
  uint32_t push_constant_bytes() const { return desc_.push_constant_bytes; }
  // The texel format of a uniform-texel-buffer binding; VK_FORMAT_UNDEFINED for a storage buffer.
  VkFormat texel_format(uint32_t index) const;
  VkPipeline pipeline() const { return pipeline_; }
  VkPipelineLayout layout() const { return layout_; }
  VkDescriptorSetLayout set_layout() const { return set_layout_; }

 private:
  void release();

  Context* context_;
  KernelDesc desc_;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

}  // namespace litgs::engine
