#include "engine/sequence.h"

#include <algorithm>
#include <stdexcept>

#include "engine/context.h"
#include "engine/vk_check.h"

namespace litgs::engine {
namespace {

// The pools' sizes (engine/sequence_pools.h).
constexpr uint32_t kSetsPerPool = SequencePools::kSetsPerPool;
constexpr uint32_t kMaxBindingsPerKernel = SequencePools::kMaxBindingsPerKernel;
constexpr uint32_t kQueriesPerPool = SequencePools::kQueriesPerPool;  // 256 dispatches

bool reads(Access a) {
  return a != Access::kWrite;
}
bool writes(Access a) {
  return a != Access::kRead;
}

}  // namespace

Sequence::Sequence(Context& context, bool timestamps)
    : context_(&context), timestamps_(timestamps && context.info().timestamps) {
  SequencePools& kept = context.sequence_pools();
  cmd_ = kept.take_command_buffer();
  try {
    fence_ = kept.take_fence();
  } catch (...) {
    release();
    throw;
  }
}

Sequence::~Sequence() {
  release();
}

// Everything goes back to the context's SequencePools for the next sequence.
void Sequence::release() {
  SequencePools& kept = context_->sequence_pools();
  if (fence_) kept.give_back(fence_);
  if (cmd_) kept.give_back(cmd_);
  for (VkDescriptorPool p : pools_) kept.give_back(p);
  for (VkQueryPool q : query_pools_) kept.give_back(q);
  fence_ = VK_NULL_HANDLE;
  cmd_ = VK_NULL_HANDLE;
  pools_.clear();
  query_pools_.clear();
}

void Sequence::reset() {
  LITGS_VK_CHECK(vkResetCommandBuffer(cmd_, 0));
  for (VkDescriptorPool p : pools_) context_->sequence_pools().give_back(p);
  pools_.clear();
  sets_in_last_pool_ = 0;
  dispatch_names_.clear();
  ticks_.clear();
  written_since_barrier_.clear();
  read_since_barrier_.clear();
  barriers_ = 0;
  recording_ = false;
  ended_ = false;
}

void Sequence::begin_if_needed() {
  if (ended_) throw std::logic_error("Sequence: recording after submit_and_wait(); call reset() first");
  if (recording_) return;
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  LITGS_VK_CHECK(vkBeginCommandBuffer(cmd_, &bi));
  recording_ = true;
}

void Sequence::before_command(const std::vector<std::pair<const Buffer*, Access>>& accesses) {
  bool hazard = false;
  for (const auto& [buffer, access] : accesses) {
    const VkBuffer b = buffer->handle();
    if (written_since_barrier_.count(b)) hazard = true;                 // read/write after write
    if (writes(access) && read_since_barrier_.count(b)) hazard = true;  // write after read
  }
  if (hazard) {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                            VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                            VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    const VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    vkCmdPipelineBarrier(cmd_, stages, stages | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
    written_since_barrier_.clear();
    read_since_barrier_.clear();
    ++barriers_;
  }
  for (const auto& [buffer, access] : accesses) track(buffer, access);
}

void Sequence::track(const Buffer* buffer, Access access) {
  if (reads(access)) read_since_barrier_.insert(buffer->handle());
  if (writes(access)) written_since_barrier_.insert(buffer->handle());
}

VkDescriptorSet Sequence::allocate_set(const Kernel& kernel) {
  VkDevice dev = context_->device();
  if (pools_.empty() || sets_in_last_pool_ == kSetsPerPool) {
    pools_.push_back(context_->sequence_pools().take_descriptor_pool());
    sets_in_last_pool_ = 0;
  }
  VkDescriptorSetLayout layout = kernel.set_layout();
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pools_.back();
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  LITGS_VK_CHECK(vkAllocateDescriptorSets(dev, &ai, &set));
  ++sets_in_last_pool_;
  return set;
}

void Sequence::dispatch_raw(const Kernel& kernel, Groups groups, std::initializer_list<Binding> bindings,
                            const void* params, uint32_t params_bytes) {
  const DeviceInfo& info = context_->info();
  if (params_bytes != kernel.push_constant_bytes())
    throw std::invalid_argument("dispatch of '" + kernel.name() + "': push constants of " +
                                std::to_string(params_bytes) + " bytes, the kernel declares " +
                                std::to_string(kernel.push_constant_bytes()));
  if (kernel.binding_count() > kMaxBindingsPerKernel)
    throw std::invalid_argument("kernel '" + kernel.name() + "' has more than " +
                                std::to_string(kMaxBindingsPerKernel) + " bindings");
  if (bindings.size() != kernel.binding_count())
    throw std::invalid_argument("dispatch of '" + kernel.name() + "': " + std::to_string(bindings.size()) +
                                " bindings given, the kernel declares " +
                                std::to_string(kernel.binding_count()));
  std::vector<bool> seen(kernel.binding_count(), false);
  for (const Binding& b : bindings) {
    if (b.index >= kernel.binding_count() || seen[b.index] || b.buffer == nullptr)
      throw std::invalid_argument("dispatch of '" + kernel.name() + "': binding " + std::to_string(b.index) +
                                  " is out of range, repeated or null");
    seen[b.index] = true;
    if (kernel.texel_format(b.index) != VK_FORMAT_UNDEFINED && b.access != Access::kRead)
      throw std::invalid_argument("dispatch of '" + kernel.name() + "': binding " + std::to_string(b.index) +
                                  " is a uniform texel buffer, which the kernel can only read");
  }
  const uint32_t g[3] = {groups.x, groups.y, groups.z};
  for (int i = 0; i < 3; ++i)
    if (g[i] > info.max_compute_workgroup_count[i])
      throw std::invalid_argument("dispatch of '" + kernel.name() + "': " + std::to_string(g[i]) +
                                  " workgroups in dimension " + std::to_string(i) +
                                  " exceed the device limit " +
                                  std::to_string(info.max_compute_workgroup_count[i]));
  if (groups.x == 0 || groups.y == 0 || groups.z == 0) return;

  begin_if_needed();
  std::vector<std::pair<const Buffer*, Access>> accesses;
  for (const Binding& b : bindings) accesses.emplace_back(b.buffer, b.access);
  before_command(accesses);

  VkDescriptorSet set = allocate_set(kernel);
  std::vector<VkDescriptorBufferInfo> infos(bindings.size());
  std::vector<VkBufferView> views(bindings.size(), VK_NULL_HANDLE);
  std::vector<VkWriteDescriptorSet> writes_(bindings.size());
  size_t i = 0;
  for (const Binding& b : bindings) {
    writes_[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes_[i].dstSet = set;
    writes_[i].dstBinding = b.index;
    writes_[i].descriptorCount = 1;
    const VkFormat texel_format = kernel.texel_format(b.index);
    if (texel_format != VK_FORMAT_UNDEFINED) {
      views[i] = b.buffer->texel_view(texel_format);
      writes_[i].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
      writes_[i].pTexelBufferView = &views[i];
    } else {
      infos[i] = {b.buffer->handle(), 0, VK_WHOLE_SIZE};
      writes_[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes_[i].pBufferInfo = &infos[i];
    }
    ++i;
  }
  vkUpdateDescriptorSets(context_->device(), static_cast<uint32_t>(writes_.size()), writes_.data(), 0,
                         nullptr);

  const uint32_t query = static_cast<uint32_t>(dispatch_names_.size()) * 2;
  VkQueryPool qpool = VK_NULL_HANDLE;
  if (timestamps_) {
    if (query / kQueriesPerPool >= query_pools_.size()) {
      query_pools_.push_back(context_->sequence_pools().take_query_pool());
    }
    qpool = query_pools_[query / kQueriesPerPool];
    vkCmdResetQueryPool(cmd_, qpool, query % kQueriesPerPool, 2);
    vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, qpool, query % kQueriesPerPool);
  }
  vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, kernel.pipeline());
  vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, kernel.layout(), 0, 1, &set, 0, nullptr);
  if (params_bytes > 0)
    vkCmdPushConstants(cmd_, kernel.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, params_bytes, params);
  vkCmdDispatch(cmd_, groups.x, groups.y, groups.z);
  if (timestamps_)
    vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, qpool, query % kQueriesPerPool + 1);
  dispatch_names_.push_back(kernel.name());
}

void Sequence::copy(const Buffer& src, const Buffer& dst, uint64_t bytes, uint64_t src_offset,
                    uint64_t dst_offset) {
  if (src_offset + bytes > src.size_bytes() || dst_offset + bytes > dst.size_bytes())
    throw std::out_of_range("copy of " + std::to_string(bytes) + " bytes from '" + src.name() + "' to '" +
                            dst.name() + "' is out of range");
  if (bytes == 0) return;
  begin_if_needed();
  before_command({{&src, Access::kRead}, {&dst, Access::kWrite}});
  VkBufferCopy region{src_offset, dst_offset, bytes};
  vkCmdCopyBuffer(cmd_, src.handle(), dst.handle(), 1, &region);
}

void Sequence::fill(const Buffer& dst, uint32_t value, uint64_t bytes, uint64_t offset) {
  if (bytes % 4 != 0 || offset % 4 != 0 || offset + bytes > dst.size_bytes())
    throw std::out_of_range("fill of " + std::to_string(bytes) + " bytes at " + std::to_string(offset) +
                            " in '" + dst.name() + "' is misaligned or out of range");
  if (bytes == 0) return;
  begin_if_needed();
  before_command({{&dst, Access::kWrite}});
  vkCmdFillBuffer(cmd_, dst.handle(), offset, bytes, value);
}

void Sequence::submit_and_wait() {
  if (!ended_) {
    begin_if_needed();
    // Make every device write visible to the host, which reads mapped memory after the fence.
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0, nullptr);
    LITGS_VK_CHECK(vkEndCommandBuffer(cmd_));
    ended_ = true;
  }
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  LITGS_VK_CHECK(vkResetFences(context_->device(), 1, &fence_));
  LITGS_VK_CHECK(vkQueueSubmit(context_->queue(), 1, &si, fence_));
  context_->wait_for_fence(fence_);

  ticks_.assign(dispatch_names_.size() * 2, 0);
  if (timestamps_) {
    for (size_t first = 0; first < ticks_.size(); first += kQueriesPerPool) {
      const uint32_t n = static_cast<uint32_t>(std::min<size_t>(kQueriesPerPool, ticks_.size() - first));
      LITGS_VK_CHECK(vkGetQueryPoolResults(context_->device(), query_pools_[first / kQueriesPerPool], 0, n,
                                           n * sizeof(uint64_t), ticks_.data() + first, sizeof(uint64_t),
                                           VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    }
  }
}

std::vector<KernelTime> Sequence::profile() const {
  std::vector<KernelTime> out;
  if (!timestamps_ || ticks_.empty()) return out;
  const double ns = context_->info().timestamp_period_ns;
  for (size_t i = 0; i < dispatch_names_.size(); ++i) {
    const double ms = static_cast<double>(ticks_[2 * i + 1] - ticks_[2 * i]) * ns * 1e-6;
    auto it = std::find_if(out.begin(), out.end(),
                           [&](const KernelTime& k) { return k.name == dispatch_names_[i]; });
    if (it == out.end()) {
      out.push_back({dispatch_names_[i], ms, 1});
    } else {
      it->ms += ms;
      ++it->dispatches;
    }
  }
  return out;
}

double Sequence::device_ms() const {
  if (!timestamps_ || ticks_.size() < 2) return 0.0;
  return static_cast<double>(ticks_.back() - ticks_.front()) * context_->info().timestamp_period_ns * 1e-6;
}

}  // namespace litgs::engine
