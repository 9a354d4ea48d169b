// Vulkan objects a Sequence needs for one recording (command buffer, fence, descriptor pools, timestamp
// query pools), kept for the next Sequence instead of being destroyed. Creating them takes the driver into
// the kernel on a GPU, and a training iteration records three sequences.
#pragma once

#include <vulkan/vulkan.h>

#include <mutex>
#include <vector>

namespace litgs::engine {

class SequencePools {
 public:
  SequencePools(VkDevice device, VkCommandPool command_pool);
  ~SequencePools();  // destroys what it holds; the device must be idle
  SequencePools(const SequencePools&) = delete;
  SequencePools& operator=(const SequencePools&) = delete;

  // The sizes of the pools it makes: descriptor sets of up to kMaxBindingsPerKernel bindings, storage or
  // uniform texel buffers (lavapipe allows 32 storage buffers per stage), timestamp queries (two per
  // dispatch).
  static constexpr uint32_t kSetsPerPool = 128;
  static constexpr uint32_t kMaxBindingsPerKernel = 32;
  static constexpr uint32_t kQueriesPerPool = 512;

  // Each take_* returns a kept object, or a new one when none is kept; it throws what LITGS_VK_CHECK throws.
  VkCommandBuffer take_command_buffer();  // primary, from the context's command pool
  VkFence take_fence();                   // unsignalled
  VkDescriptorPool take_descriptor_pool();
  VkQueryPool take_query_pool();  // timestamps

  // Each give_back resets the object for its next use (never throws); it must not be in use on the device.
  void give_back(VkCommandBuffer cmd) noexcept;
  void give_back(VkFence fence) noexcept;
  void give_back(VkDescriptorPool pool) noexcept;
  void give_back(VkQueryPool pool) noexcept;

 private:
  VkDevice device_;
  VkCommandPool command_pool_;
  std::mutex mutex_;
  std::vector<VkCommandBuffer> command_buffers_;
  std::vector<VkFence> fences_;
  std::vector<VkDescriptorPool> descriptor_pools_;
  std::vector<VkQueryPool> query_pools_;
};

}  // namespace litgs::engine
