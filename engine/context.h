// The Vulkan compute context: instance, one device, one compute queue, a command pool and the device facts.
// Knows nothing of splatting.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "engine/sequence_pools.h"

namespace litgs::engine {

class Buffer;

struct ContextOptions {
  // Which device: an index into the Vulkan 1.2+ devices, or a case-insensitive substring of the name.
  // Empty: the first discrete GPU, else the first device. Environment: LITGS_DEVICE.
  std::string device_selector;
  // Enable VK_LAYER_KHRONOS_validation (with synchronization validation) and collect its messages.
  // Environment: LITGS_VALIDATION=1.
  bool validation = false;

  // Options from LITGS_DEVICE and LITGS_VALIDATION.
  static ContextOptions from_environment();
  // Throws std::invalid_argument naming the bad field.
  void check() const;
};

struct MemoryHeapInfo {
  uint64_t size_bytes = 0;
  bool device_local = false;
};

// What the engine and its kernels need to know about the chosen device.
struct DeviceInfo {
  uint32_t index = 0;       // position among the usable (Vulkan 1.2+) devices
  std::string name;         // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string type;         // "discrete", "integrated", "virtual", "cpu", "other"
  std::string driver_name;  // e.g. "llvmpipe"
  std::string driver_info;  // e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
  std::string api_version;  // "1.3.230"
  uint32_t vendor_id = 0;
  uint32_t subgroup_size = 0;      // default subgroup size of compute shaders
  uint32_t min_subgroup_size = 0;  // with subgroup size control; equal to subgroup_size otherwise
  uint32_t max_subgroup_size = 0;
  bool compute_full_subgroups = false;    // a pipeline can require full subgroups of a chosen size
  bool subgroup_ballot = false;           // GL_KHR_shader_subgroup_ballot in compute
  bool subgroup_arithmetic = false;       // GL_KHR_shader_subgroup_arithmetic in compute
  bool float_atomic_add = false;          // VK_EXT_shader_atomic_float: shaderBufferFloat32AtomicAdd
  uint64_t max_storage_buffer_range = 0;  // bytes one storage-buffer binding may span
  uint64_t max_memory_allocation_size = 0;
  uint32_t max_push_constants_size = 0;
  uint32_t max_compute_shared_memory_size = 0;
  uint32_t max_per_stage_storage_buffers = 0;  // storage-buffer bindings one kernel may have
  uint32_t max_per_stage_sampled_images = 0;   // uniform-texel-buffer bindings one kernel may have
  uint64_t max_texel_buffer_elements = 0;      // elements one uniform-texel-buffer binding may span
  uint32_t max_compute_workgroup_invocations = 0;
  uint32_t max_compute_workgroup_count[3] = {0, 0, 0};
  bool timestamps = false;           // compute queue supports timestamps
  double timestamp_period_ns = 0.0;  // nanoseconds per timestamp tick
  std::vector<MemoryHeapInfo> memory_heaps;
};

class Context {
 public:
  // Creates the instance and device. Throws NoDeviceError when there is no usable Vulkan device or driver.
  explicit Context(const ContextOptions& options = ContextOptions::from_environment());
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const DeviceInfo& info() const { return info_; }
  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  VkCommandPool command_pool() const { return command_pool_; }
  SequencePools& sequence_pools() { return *sequence_pools_; }

  // A memory type index with all `required` flags, preferring one that also has `preferred`.
  uint32_t find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                            VkMemoryPropertyFlags preferred) const;
  VkMemoryPropertyFlags memory_type_flags(uint32_t type_index) const;

  // Records and submits a one-off command buffer, then waits for it (uploads, downloads).
  template <class Record>
  void run_once(Record&& record) {
    VkCommandBuffer cmd = begin_one_off();
    try {
      record(cmd);
    } catch (...) {
      vkFreeCommandBuffers(device_, command_pool_, 1, &cmd);
      throw;
    }
    end_one_off(cmd);
  }
  VkCommandBuffer begin_one_off();
  void end_one_off(VkCommandBuffer cmd);  // submits, waits and gives the command buffer back

  // Waits for a submitted fence. On a GPU it polls for up to 20 ms first: a blocking wait returns only when
  // the driver's interrupt wakes the thread, which in a VM took a noticeable share of a training iteration
  // (three submits each; docs/experiments.md, "the first runs on a real GPU", issue 18). A CPU device
  // (lavapipe) needs every core for the work itself, so there the thread blocks at once.
  void wait_for_fence(VkFence fence);

  // Runs `use` with the context's kept host-visible staging buffer of at least `bytes` (bytes at most
  // kKeptStagingBytes), under a lock: up- and downloads of renders and small arrays reuse it instead of
  // allocating host-visible memory each time. On an H200, `serve`'s time per render grew with the bytes it
  // downloaded, far beyond the render's own time, which points at those allocations (docs/results.md, "On a
  // GPU: NVIDIA H200"); the change could not be measured there afterwards.
  static constexpr uint64_t kKeptStagingBytes = 8ull << 20;
  uint64_t kept_staging_bytes();  // its size now (0 before the first staged transfer)
  template <class Use>
  void with_kept_staging(uint64_t bytes, Use&& use) {
    std::lock_guard<std::mutex> lock(staging_mutex_);
    use(kept_staging(bytes));
  }

  // Validation layer messages (only with ContextOptions::validation).
  bool validation_enabled() const { return validation_; }
  size_t validation_error_count() const;
  std::vector<std::string> validation_messages() const;
  void clear_validation_messages();

  // Devices the loader sees that meet the engine's needs; never throws for "no device" (returns empty).
  static std::vector<DeviceInfo> list_devices();

 private:
  friend struct ContextCallbacks;
  void record_validation_message(bool is_error, const std::string& message);
  void release();                        // destroys every handle; safe on a partly built context
  Buffer& kept_staging(uint64_t bytes);  // grows it when needed; staging_mutex_ held

  DeviceInfo info_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkFence one_off_fence_ = VK_NULL_HANDLE;
  std::unique_ptr<SequencePools> sequence_pools_;
  std::mutex staging_mutex_;
  std::unique_ptr<Buffer> staging_;  // see with_kept_staging

  bool validation_ = false;
  mutable std::mutex messages_mutex_;
  std::vector<std::string> messages_;
  size_t error_count_ = 0;
};

}  // namespace litgs::engine
