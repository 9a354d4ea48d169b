#include "engine/buffer.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "engine/context.h"
#include "engine/vk_check.h"

namespace litgs::engine {
namespace {

std::string mib(uint64_t bytes) {
  std::ostringstream s;
  s.precision(4);
  s << static_cast<double>(bytes) / (1024.0 * 1024.0) << " MiB (" << bytes << " bytes)";
  return s.str();
}

void check_limit(const std::string& name, uint64_t size, uint64_t limit, const char* limit_name,
                 const Context& ctx) {
  if (limit != 0 && size > limit)
    throw std::length_error("buffer '" + name + "' needs " + mib(size) + ", over the device's " + limit_name +
                            " of " + mib(limit) + " on " + ctx.info().name +
                            "; split it (structure of arrays) or use fewer elements");
}

std::atomic<uint64_t> g_live_bytes{0};
std::atomic<uint64_t> g_peak_bytes{0};

// The live allocations by their memory handle (it moves with the Buffer), and their sum by name at the peak.
std::mutex g_registry_mutex;
std::unordered_map<VkDeviceMemory, std::pair<std::string, uint64_t>> g_live_allocations;
std::map<std::string, uint64_t> g_peak_by_name;

void count_allocation(VkDeviceMemory memory, const std::string& name, uint64_t bytes) {
  const uint64_t live = g_live_bytes.fetch_add(bytes) + bytes;
  uint64_t peak = g_peak_bytes.load();
  bool new_peak = false;
  while (live > peak && !(new_peak = g_peak_bytes.compare_exchange_weak(peak, live))) {
  }
  std::lock_guard lock(g_registry_mutex);
  g_live_allocations[memory] = {name, bytes};
  if (new_peak) {  // allocations are rare (sizes grow by steps): a snapshot per new peak is cheap
    g_peak_by_name.clear();
    for (const auto& [handle, entry] : g_live_allocations) g_peak_by_name[entry.first] += entry.second;
  }
}

void count_release(VkDeviceMemory memory, uint64_t bytes) {
  g_live_bytes.fetch_sub(bytes);
  std::lock_guard lock(g_registry_mutex);
  g_live_allocations.erase(memory);
}

}  // namespace

uint64_t Buffer::live_bytes() {
  return g_live_bytes.load();
}
uint64_t Buffer::peak_bytes() {
  return g_peak_bytes.load();
}
std::vector<std::pair<std::string, uint64_t>> Buffer::peak_breakdown() {
  std::vector<std::pair<std::string, uint64_t>> out;
  {
    std::lock_guard lock(g_registry_mutex);
    out.assign(g_peak_by_name.begin(), g_peak_by_name.end());
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  return out;
}

uint32_t texel_format_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_R32_SFLOAT:
      return 4;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return 16;
    default:
      throw std::invalid_argument("texel format " + std::to_string(format) +
                                  " is not one the engine binds (R32_UINT, R32_SFLOAT, R32G32B32A32_SFLOAT)");
  }
}

Buffer::Buffer(Context& context, std::string name, uint64_t size_bytes, MemoryKind kind)
    : context_(&context), name_(std::move(name)), size_bytes_(size_bytes) {
  const DeviceInfo& info = context.info();
  check_limit(name_, size_bytes, info.max_storage_buffer_range, "maxStorageBufferRange", context);
  check_limit(name_, size_bytes, info.max_memory_allocation_size, "maxMemoryAllocationSize", context);

  // Vulkan forbids empty buffers; an empty array still gets a valid handle to bind.
  const VkDeviceSize alloc_size = size_bytes == 0 ? 16 : (size_bytes + 3) & ~VkDeviceSize{3};
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = alloc_size;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
              VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
              VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkDevice dev = context.device();
  LITGS_VK_CHECK(vkCreateBuffer(dev, &bci, nullptr, &buffer_));

  try {
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(dev, buffer_, &req);
    const VkMemoryPropertyFlags host =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    // Device-local memory that is also host-visible (CPU drivers, resizable BAR) is mapped: no staging.
    const uint32_t type =
        kind != MemoryKind::kHostVisible
            ? context.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, host)
            : context.find_memory_type(req.memoryTypeBits, host, VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    const VkResult r = vkAllocateMemory(dev, &ai, nullptr, &memory_);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
      throw std::length_error("out of memory allocating buffer '" + name_ + "' of " + mib(req.size) + " on " +
                              context.info().name);
    LITGS_VK_CHECK(r);
    allocated_bytes_ = req.size;
    count_allocation(memory_, name_, allocated_bytes_);
    LITGS_VK_CHECK(vkBindBufferMemory(dev, buffer_, memory_, 0));
    if (kind != MemoryKind::kDeviceOnly && (context.memory_type_flags(type) & host) == host)
      LITGS_VK_CHECK(vkMapMemory(dev, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
  } catch (...) {
    release();
    throw;
  }
}

Buffer::~Buffer() {
  release();
}

Buffer::Buffer(Buffer&& other) noexcept
    : context_(other.context_),
      name_(std::move(other.name_)),
      size_bytes_(other.size_bytes_),
      buffer_(std::exchange(other.buffer_, VK_NULL_HANDLE)),
      memory_(std::exchange(other.memory_, VK_NULL_HANDLE)),
      mapped_(std::exchange(other.mapped_, nullptr)),
      allocated_bytes_(std::exchange(other.allocated_bytes_, 0)),
      texel_views_(std::exchange(other.texel_views_, {})) {}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    release();
    context_ = other.context_;
    name_ = std::move(other.name_);
    size_bytes_ = other.size_bytes_;
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    mapped_ = std::exchange(other.mapped_, nullptr);
    allocated_bytes_ = std::exchange(other.allocated_bytes_, 0);
    texel_views_ = std::exchange(other.texel_views_, {});
  }
  return *this;
}

void Buffer::release() {
  if (!context_) return;
  VkDevice dev = context_->device();
  for (const auto& [format, view] : texel_views_) vkDestroyBufferView(dev, view, nullptr);
  texel_views_.clear();
  if (mapped_) vkUnmapMemory(dev, memory_);
  if (buffer_) vkDestroyBuffer(dev, buffer_, nullptr);
  if (allocated_bytes_) count_release(memory_, allocated_bytes_);
  if (memory_) vkFreeMemory(dev, memory_, nullptr);
  allocated_bytes_ = 0;
  mapped_ = nullptr;
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
}

VkBufferView Buffer::texel_view(VkFormat format) const {
  for (const auto& [f, view] : texel_views_)
    if (f == format) return view;
  const uint32_t element_bytes = texel_format_bytes(format);
  // The buffer as created (a multiple of 4 bytes, 16 when empty): the view ends at its last whole element.
  const uint64_t elements = (size_bytes_ == 0 ? 16 : (size_bytes_ + 3) & ~uint64_t{3}) / element_bytes;
  const DeviceInfo& info = context_->info();
  if (elements == 0)
    throw std::invalid_argument("buffer '" + name_ + "' of " + std::to_string(size_bytes_) +
                                " bytes is smaller than one texel element of " +
                                std::to_string(element_bytes));
  if (elements > info.max_texel_buffer_elements)
    throw std::length_error("buffer '" + name_ + "' of " + std::to_string(size_bytes_) + " bytes holds " +
                            std::to_string(elements) + " texel elements, more than maxTexelBufferElements " +
                            std::to_string(info.max_texel_buffer_elements) + " of " + info.name);
  VkBufferViewCreateInfo vci{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  vci.buffer = buffer_;
  vci.format = format;
  vci.offset = 0;
  vci.range = VK_WHOLE_SIZE;
  VkBufferView view = VK_NULL_HANDLE;
  LITGS_VK_CHECK(vkCreateBufferView(context_->device(), &vci, nullptr, &view));
  texel_views_.emplace_back(format, view);
  return view;
}

void Buffer::check_range(uint64_t bytes, uint64_t offset, const char* what) const {
  if (offset > size_bytes_ || bytes > size_bytes_ - offset)
    throw std::out_of_range(std::string(what) + " of " + std::to_string(bytes) + " bytes at offset " +
                            std::to_string(offset) + " is outside buffer '" + name_ + "' of " +
                            std::to_string(size_bytes_) + " bytes");
}

void Buffer::upload(const void* data, uint64_t bytes, uint64_t offset) {
  check_range(bytes, offset, "upload");
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    return;
  }
  const auto through = [&](Buffer& staging) {
    std::memcpy(staging.mapped_, data, bytes);
    context_->run_once([&](VkCommandBuffer cmd) {
      VkBufferCopy region{0, offset, bytes};
      vkCmdCopyBuffer(cmd, staging.handle(), buffer_, 1, &region);
    });
  };
  if (bytes <= Context::kKeptStagingBytes) return context_->with_kept_staging(bytes, through);
  Buffer staging(*context_, name_ + " (staging)", bytes, MemoryKind::kHostVisible);
  through(staging);
}

void Buffer::download(void* data, uint64_t bytes, uint64_t offset) const {
  check_range(bytes, offset, "download");
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    return;
  }
  const auto through = [&](Buffer& staging) {
    context_->run_once([&](VkCommandBuffer cmd) {
      VkBufferCopy region{offset, 0, bytes};
      vkCmdCopyBuffer(cmd, buffer_, staging.handle(), 1, &region);
    });
    std::memcpy(data, staging.mapped_, bytes);
  };
  if (bytes <= Context::kKeptStagingBytes) return context_->with_kept_staging(bytes, through);
  Buffer staging(*context_, name_ + " (readback)", bytes, MemoryKind::kHostVisible);
  through(staging);
}

}  // namespace litgs::engine
