#include "engine/sequence_pools.h"

namespace litgs::engine {
namespace {

template <class T>
T pop_or_null(std::vector<T>& kept) {
  if (kept.empty()) return VK_NULL_HANDLE;
  const T object = kept.back();
  kept.pop_back();
  return object;
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
  std::lock_guard<std::mutex> lock(mutex_);
  return pop_or_null(command_buffers_);
}

VkFence SequencePools::take_fence() {
  std::lock_guard<std::mutex> lock(mutex_);
  return pop_or_null(fences_);
}

VkDescriptorPool SequencePools::take_descriptor_pool() {
  std::lock_guard<std::mutex> lock(mutex_);
  return pop_or_null(descriptor_pools_);
}

VkQueryPool SequencePools::take_query_pool() {
  std::lock_guard<std::mutex> lock(mutex_);
  return pop_or_null(query_pools_);
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
