// A compute kernel: a pipeline built from embedded SPIR-V, with its storage-buffer bindings declared once,
// a typed push-constant block and specialization constants.
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

struct KernelDesc {
  std::string name;                  // for profiles and error messages, e.g. "sort/radix_scatter"
  std::span<const uint32_t> spirv;   // embedded words (kernels/spirv_registry.h)
  uint32_t binding_count = 0;        // storage buffers at bindings 0 .. binding_count-1 of set 0
  uint32_t push_constant_bytes = 0;  // size of the push-constant struct, 0 if none
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
