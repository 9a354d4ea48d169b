// A recorded sequence of dispatches and transfers: one command buffer, one submit. Each command states
// which buffers it reads and writes; the sequence inserts a barrier only where a hazard follows from that.
// Each dispatch is bracketed by GPU timestamps, so a submit yields a per-kernel profile.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <initializer_list>
#include <string>
#include <unordered_set>
#include <vector>

#include "engine/buffer.h"
#include "engine/kernel.h"

namespace litgs::engine {

enum class Access { kRead, kWrite, kReadWrite };

// A buffer bound at one of a kernel's binding indices (the kernel's shared header names the indices).
struct Binding {
  uint32_t index;
  const Buffer* buffer;
  Access access;
};

struct Groups {
  uint32_t x = 1, y = 1, z = 1;
};

struct KernelTime {
  std::string name;
  double ms = 0.0;  // summed over this kernel's dispatches in the last submit
  uint32_t dispatches = 0;
};

class Sequence {
 public:
  explicit Sequence(Context& context, bool timestamps = true);
  ~Sequence();
  Sequence(const Sequence&) = delete;
  Sequence& operator=(const Sequence&) = delete;

  // Records one dispatch. Every binding 0 .. kernel.binding_count()-1 must be given exactly once.
  // A dispatch of zero groups records nothing.
  template <class Params>
  void dispatch(const Kernel& kernel, Groups groups, std::initializer_list<Binding> bindings,
                const Params& params) {
    static_assert(sizeof(Params) <= 128, "push constants are limited to 128 bytes on many devices");
    dispatch_raw(kernel, groups, bindings, &params, sizeof(Params));
  }
  void dispatch(const Kernel& kernel, Groups groups, std::initializer_list<Binding> bindings) {
    dispatch_raw(kernel, groups, bindings, nullptr, 0);
  }
  void dispatch_raw(const Kernel& kernel, Groups groups, std::initializer_list<Binding> bindings,
                    const void* params, uint32_t params_bytes);

  void copy(const Buffer& src, const Buffer& dst, uint64_t bytes, uint64_t src_offset = 0,
            uint64_t dst_offset = 0);
  // Fills `bytes` (a multiple of 4) from `offset` with the 32-bit `value`.
  void fill(const Buffer& dst, uint32_t value, uint64_t bytes, uint64_t offset = 0);

  // Ends recording (first time), submits and waits. A recorded sequence can be submitted again (replay).
  void submit_and_wait();
  // Drops everything recorded, to record anew.
  void reset();

  // Per-kernel GPU times of the last submit, in order of first dispatch; empty without timestamps.
  std::vector<KernelTime> profile() const;
  // GPU time from the first dispatch's start to the last one's end in the last submit.
  double device_ms() const;
  size_t dispatch_count() const { return dispatch_names_.size(); }
  size_t barrier_count() const { return barriers_; }

 private:
  void begin_if_needed();
  // Emits a barrier if any access conflicts with one since the last barrier, then records the accesses.
  void before_command(const std::vector<std::pair<const Buffer*, Access>>& accesses);
  void track(const Buffer* buffer, Access access);
  VkDescriptorSet allocate_set(const Kernel& kernel);
  void release();

  Context* context_;
  bool timestamps_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool recording_ = false;
  bool ended_ = false;
  std::vector<VkDescriptorPool> pools_;
  uint32_t sets_in_last_pool_ = 0;
  std::vector<VkQueryPool> query_pools_;
  std::vector<std::string> dispatch_names_;
  std::vector<uint64_t> ticks_;  // 2 per dispatch after a submit
  std::unordered_set<VkBuffer> written_since_barrier_;
  std::unordered_set<VkBuffer> read_since_barrier_;
  size_t barriers_ = 0;
};

}  // namespace litgs::engine
