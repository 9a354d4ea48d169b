#include "engine/sequence_pools.h"

#include "engine/vk_check.h"

namespace litgs::engine {
namespace {

// The last kept object, else a new one from `make` (made outside the lock).
template <class T, class Make>
T take_or_make(std::mutex& mutex, std::vector<T>& kept, Make&& make) {
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!kept.empty()) {
      const T object = kept.back();
      kept.pop_back();
      return object;
    }
  }
  return make();
}

}  // namespace

SequencePools::SequencePools(VkDevice device, VkCommandPool command_pool)
    : device_(device), command_pool_(command_pool) {}

SequencePools::~SequencePools() {
  if (!command_buffers_.empty())
    vkFreeCommandBuffers(device_, command_pool_, static_cast<uint32_t>(command_buffers_.size()),
                         command_buffers_.data());
  for (VkFence f : fences_) vkDestroyFence(device_, f, nullptr);
  for (VkDescriptorPool p : descriptor_pools_) vkDestroyDescriptorPool(device_, p, nullptr);
  for (VkQueryPool q : query_pools_) vkDestroyQueryPool(device_, q, nullptr);
}

VkCommandBuffer SequencePools::take_command_buffer() {
  return take_or_make(mutex_, command_buffers_, [&] {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = command_pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    LITGS_VK_CHECK(vkAllocateCommandBuffers(device_, &ai, &cmd));
    return cmd;
  });
}

VkFence SequencePools::take_fence() {
  return take_or_make(mutex_, fences_, [&] {
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    LITGS_VK_CHECK(vkCreateFence(device_, &fci, nullptr, &fence));
    return fence;
  });
}

VkDescriptorPool SequencePools::take_descriptor_pool() {
  return take_or_make(mutex_, descriptor_pools_, [&] {
    // Any of a kernel's bindings may be either kind (engine/kernel.h).
    const VkDescriptorPoolSize sizes[] = {
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kSetsPerPool * kMaxBindingsPerKernel},
        {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, kSetsPerPool * kMaxBindingsPerKernel}};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = kSetsPerPool;
    pci.poolSizeCount = 2;
    pci.pPoolSizes = sizes;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    LITGS_VK_CHECK(vkCreateDescriptorPool(device_, &pci, nullptr, &pool));
    return pool;
  });
}

VkQueryPool SequencePools::take_query_pool() {
  return take_or_make(mutex_, query_pools_, [&] {
    VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qci.queryCount = kQueriesPerPool;
    VkQueryPool pool = VK_NULL_HANDLE;
    LITGS_VK_CHECK(vkCreateQueryPool(device_, &qci, nullptr, &pool));
    return pool;
  });
}

// A give_back never throws (sequences give back from their destructors): an object that fails to reset
// (a lost device) is destroyed instead of kept.
void SequencePools::give_back(VkCommandBuffer cmd) noexcept {
  if (vkResetCommandBuffer(cmd, 0) != VK_SUCCESS)
    return vkFreeCommandBuffers(device_, command_pool_, 1, &cmd);
  std::lock_guard<std::mutex> lock(mutex_);
  command_buffers_.push_back(cmd);
}

void SequencePools::give_back(VkFence fence) noexcept {
  if (vkResetFences(device_, 1, &fence) != VK_SUCCESS) return vkDestroyFence(device_, fence, nullptr);
  std::lock_guard<std::mutex> lock(mutex_);
  fences_.push_back(fence);
}

void SequencePools::give_back(VkDescriptorPool pool) noexcept {
  if (vkResetDescriptorPool(device_, pool, 0) != VK_SUCCESS)
    return vkDestroyDescriptorPool(device_, pool, nullptr);
  std::lock_guard<std::mutex> lock(mutex_);
  descriptor_pools_.push_back(pool);
}

void SequencePools::give_back(VkQueryPool pool) noexcept {
  // Queries are reset in the command buffer before each use (vkCmdResetQueryPool), so nothing to do here.
  std::lock_guard<std::mutex> lock(mutex_);
  query_pools_.push_back(pool);
}

}  // namespace litgs::engine
