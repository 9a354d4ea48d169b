// Device buffers: RAII, named, size-checked against the device limits, with upload and download.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace litgs::engine {

class Context;

enum class MemoryKind {
  kDeviceLocal,  // fastest for kernels; up/downloads go through a staging buffer unless it is host-visible
  kHostVisible,  // host-coherent, mapped: staging and readback
  kDeviceOnly,   // device-local and never mapped, even where it could be: up/downloads always go through
                 // staging (as they do on a discrete GPU; tests use it to run that path on lavapipe)
};

// Bytes of one element of a texel format the engine binds (engine/kernel.h TexelBinding); throws
// std::invalid_argument for any other format.
uint32_t texel_format_bytes(VkFormat format);

// One VkBuffer with its own memory, usable as a storage buffer, a uniform texel buffer (through the views it
// makes) and a transfer source and destination.
class Buffer {
 public:
  // Throws std::length_error naming the buffer and the limit when `size_bytes` exceeds the device's
  // maxStorageBufferRange, maxMemoryAllocationSize or the size of the heap it would live in.
  Buffer(Context& context, std::string name, uint64_t size_bytes, MemoryKind kind = MemoryKind::kDeviceLocal);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  // Bytes of device memory held by all live buffers of the process, and the most ever held at once.
  static uint64_t live_bytes();
  static uint64_t peak_bytes();
  // Where the peak went: the bytes of the buffers alive when peak_bytes() was reached, summed by buffer name
  // (buffers of one role share a name: "train: view targets"), most first.
  static std::vector<std::pair<std::string, uint64_t>> peak_breakdown();

  const std::string& name() const { return name_; }
  VkBuffer handle() const { return buffer_; }
  uint64_t size_bytes() const { return size_bytes_; }  // as requested; 0 is allowed
  bool host_visible() const { return mapped_ != nullptr; }
  Context& context() const { return *context_; }

  // Copies bytes in or out, directly when the memory is mapped, else through a staging buffer.
  // Throws std::out_of_range when [offset, offset + bytes) is outside the buffer.
  void upload(const void* data, uint64_t bytes, uint64_t offset = 0);
  void download(void* data, uint64_t bytes, uint64_t offset = 0) const;

  // A view of the whole buffer as elements of `format`, made on first use and kept as long as the buffer.
  // Throws std::length_error naming the buffer when it holds more elements than maxTexelBufferElements.
  // Not thread-safe (the view cache is unguarded): a buffer is bound from one recording thread at a time.
  VkBufferView texel_view(VkFormat format) const;

 private:
  void release();
  void check_range(uint64_t bytes, uint64_t offset, const char* what) const;

  Context* context_ = nullptr;
  std::string name_;
  uint64_t size_bytes_ = 0;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  uint64_t allocated_bytes_ = 0;
  mutable std::vector<std::pair<VkFormat, VkBufferView>> texel_views_;  // made by texel_view()
};

// A typed array on the device: `count` elements of T (trivially copyable).
template <class T>
class DeviceArray {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  DeviceArray(Context& context, std::string name, size_t count, MemoryKind kind = MemoryKind::kDeviceLocal)
      : buffer_(context, std::move(name), static_cast<uint64_t>(count) * sizeof(T), kind), count_(count) {}

  size_t size() const { return count_; }
  Buffer& buffer() { return buffer_; }
  const Buffer& buffer() const { return buffer_; }
  const std::string& name() const { return buffer_.name(); }

  void upload(std::span<const T> values, size_t first = 0) {
    buffer_.upload(values.data(), values.size_bytes(), static_cast<uint64_t>(first) * sizeof(T));
  }
  std::vector<T> download(size_t first = 0, size_t count = SIZE_MAX) const {
    if (count == SIZE_MAX) count = first < count_ ? count_ - first : 0;
    std::vector<T> out(count);
    buffer_.download(out.data(), static_cast<uint64_t>(count) * sizeof(T),
                     static_cast<uint64_t>(first) * sizeof(T));
    return out;
  }

 private:
  Buffer buffer_;
  size_t count_;
};

}  // namespace litgs::engine
