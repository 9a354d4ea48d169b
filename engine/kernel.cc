#include "engine/kernel.h"

#include <stdexcept>

#include "engine/buffer.h"
#include "engine/context.h"
#include "engine/vk_check.h"

namespace litgs::engine {

namespace {

// Each texel binding names a binding of the kernel once, with a format the device reads as uniform texels.
void check_texel_bindings(const Context& context, const KernelDesc& desc) {
  std::vector<bool> seen(desc.binding_count, false);
  for (const TexelBinding& t : desc.texel_bindings) {
    if (t.index >= desc.binding_count || seen[t.index])
      throw std::invalid_argument("kernel '" + desc.name + "': texel binding " + std::to_string(t.index) +
                                  " is out of range or repeated");
    seen[t.index] = true;
    texel_format_bytes(t.format);  // throws for a format the engine does not size
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(context.physical_device(), t.format, &props);
    if (!(props.bufferFeatures & VK_FORMAT_FEATURE_UNIFORM_TEXEL_BUFFER_BIT))
      throw std::invalid_argument("kernel '" + desc.name + "': binding " + std::to_string(t.index) +
                                  ": format " + std::to_string(t.format) +
                                  " is not a uniform texel format on " + context.info().name);
  }
}

}  // namespace

Kernel::Kernel(Context& context, KernelDesc desc) : context_(&context), desc_(std::move(desc)) {
  const DeviceInfo& info = context.info();
  if (desc_.spirv.empty() || desc_.spirv[0] != 0x07230203u)
    throw std::invalid_argument("kernel '" + desc_.name + "': SPIR-V is empty or lacks the magic number");
  if (desc_.push_constant_bytes > info.max_push_constants_size)
    throw std::invalid_argument(
        "kernel '" + desc_.name + "': push constants of " + std::to_string(desc_.push_constant_bytes) +
        " bytes exceed maxPushConstantsSize " + std::to_string(info.max_push_constants_size));
  check_texel_bindings(context, desc_);
  const uint32_t texel_count = static_cast<uint32_t>(desc_.texel_bindings.size());
  const uint32_t storage_count = desc_.binding_count - texel_count;
  if (storage_count > info.max_per_stage_storage_buffers)
    throw std::invalid_argument("kernel '" + desc_.name + "': " + std::to_string(storage_count) +
                                " storage buffers exceed maxPerStageDescriptorStorageBuffers " +
                                std::to_string(info.max_per_stage_storage_buffers) + " of " + info.name);
  if (texel_count > info.max_per_stage_sampled_images)
    throw std::invalid_argument("kernel '" + desc_.name + "': " + std::to_string(texel_count) +
                                " uniform texel buffers exceed maxPerStageDescriptorSampledImages " +
                                std::to_string(info.max_per_stage_sampled_images) + " of " + info.name);
  const uint32_t sg = desc_.required_subgroup_size;
  const bool fixed_size = info.min_subgroup_size == info.max_subgroup_size && sg == info.subgroup_size;
  if (sg != 0 && !fixed_size &&
      (!info.compute_full_subgroups || sg < info.min_subgroup_size || sg > info.max_subgroup_size))
    throw std::invalid_argument("kernel '" + desc_.name + "' needs subgroups of exactly " +
                                std::to_string(sg) + " invocations, which " + info.name +
                                " cannot guarantee (subgroup size " + std::to_string(info.min_subgroup_size) +
                                ".." + std::to_string(info.max_subgroup_size) + ", subgroup size control " +
                                (info.compute_full_subgroups ? "yes" : "no") + ")");

  VkDevice dev = context.device();
  try {
    VkShaderModuleCreateInfo mci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    mci.codeSize = desc_.spirv.size_bytes();
    mci.pCode = desc_.spirv.data();
    LITGS_VK_CHECK(vkCreateShaderModule(dev, &mci, nullptr, &module_));

    std::vector<VkDescriptorSetLayoutBinding> bindings(desc_.binding_count);
    for (uint32_t i = 0; i < desc_.binding_count; ++i) {
      bindings[i].binding = i;
      bindings[i].descriptorType = texel_format(i) != VK_FORMAT_UNDEFINED
                                       ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                       : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      bindings[i].descriptorCount = 1;
      bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo sci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    sci.bindingCount = desc_.binding_count;
    sci.pBindings = bindings.data();
    LITGS_VK_CHECK(vkCreateDescriptorSetLayout(dev, &sci, nullptr, &set_layout_));

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, desc_.push_constant_bytes};
    VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    lci.setLayoutCount = 1;
    lci.pSetLayouts = &set_layout_;
    lci.pushConstantRangeCount = desc_.push_constant_bytes > 0 ? 1 : 0;
    lci.pPushConstantRanges = &range;
    LITGS_VK_CHECK(vkCreatePipelineLayout(dev, &lci, nullptr, &layout_));

    std::vector<VkSpecializationMapEntry> entries;
    std::vector<uint32_t> values;
    for (const SpecConstant& c : desc_.spec_constants) {
      entries.push_back({c.id, static_cast<uint32_t>(values.size() * sizeof(uint32_t)), sizeof(uint32_t)});
      values.push_back(c.value);
    }
    VkSpecializationInfo spec{static_cast<uint32_t>(entries.size()), entries.data(),
                              values.size() * sizeof(uint32_t), values.data()};

    VkPipelineShaderStageRequiredSubgroupSizeCreateInfo required{
        VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_REQUIRED_SUBGROUP_SIZE_CREATE_INFO};
    required.requiredSubgroupSize = sg;
    VkComputePipelineCreateInfo pci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pci.stage.module = module_;
    pci.stage.pName = "main";
    pci.stage.pSpecializationInfo = entries.empty() ? nullptr : &spec;
    if (sg != 0 && info.compute_full_subgroups) {
      pci.stage.flags = VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT;
      pci.stage.pNext = &required;
    }
    pci.layout = layout_;
    LITGS_VK_CHECK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &pci, nullptr, &pipeline_));
  } catch (...) {
    release();
    throw;
  }
}

VkFormat Kernel::texel_format(uint32_t index) const {
  for (const TexelBinding& t : desc_.texel_bindings)
    if (t.index == index) return t.format;
  return VK_FORMAT_UNDEFINED;
}

Kernel::~Kernel() {
  release();
}

void Kernel::release() {
  VkDevice dev = context_->device();
  if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
  if (module_) vkDestroyShaderModule(dev, module_, nullptr);
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
  module_ = VK_NULL_HANDLE;
}

}  // namespace litgs::engine
