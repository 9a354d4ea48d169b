#include "engine/context.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "engine/buffer.h"
#include "engine/vk_check.h"

namespace litgs::engine {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr const char* kInstallHint =
    "install a Vulkan driver: on Debian `apt-get install mesa-vulkan-drivers` (lavapipe, software) or your "
    "GPU "
    "vendor's driver; `vulkaninfo --summary` (package vulkan-tools) lists what the loader sees";

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string version_string(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    default:
      return "other";
  }
}

bool has_device_extension(VkPhysicalDevice pd, const char* name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
  return std::any_of(exts.begin(), exts.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

int compute_queue_family(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
  // Prefer a family with compute; graphics+compute families are the universal choice.
  for (uint32_t i = 0; i < n; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return static_cast<int>(i);
  return -1;
}

// Everything the engine reads about one physical device, and which optional features it will enable.
struct Candidate {
  VkPhysicalDevice handle = VK_NULL_HANDLE;
  DeviceInfo info;
  VkPhysicalDeviceType device_type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t api = 0;
  int queue_family = -1;
  bool size_control_core = false;  // Vulkan 1.3 features
  bool size_control_ext = false;   // VK_EXT_subgroup_size_control on a 1.2 device
  bool atomic_float_ext = false;
};

Candidate describe(VkPhysicalDevice pd) {
  Candidate c;
  c.handle = pd;
  VkPhysicalDeviceProperties base{};
  vkGetPhysicalDeviceProperties(pd, &base);
  c.api = base.apiVersion;
  c.device_type = base.deviceType;
  c.queue_family = compute_queue_family(pd);

  const bool api13 = base.apiVersion >= VK_API_VERSION_1_3;
  const bool ext_size_control =
      !api13 && has_device_extension(pd, VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME);
  c.atomic_float_ext = has_device_extension(pd, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);

  VkPhysicalDeviceSubgroupSizeControlProperties size_props{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_PROPERTIES};
  VkPhysicalDeviceVulkan11Properties props11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES};
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceMaintenance3Properties maint3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props2.pNext = &props11;
  props11.pNext = &driver;
  driver.pNext = &maint3;
  if (api13 || ext_size_control) maint3.pNext = &size_props;
  vkGetPhysicalDeviceProperties2(pd, &props2);

  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomic_features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
  VkPhysicalDeviceSubgroupSizeControlFeatures size_features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES};
  VkPhysicalDeviceFeatures2 features2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  void** tail = &features2.pNext;
  if (c.atomic_float_ext) {
    *tail = &atomic_features;
    tail = &atomic_features.pNext;
  }
  if (api13 || ext_size_control) *tail = &size_features;
  vkGetPhysicalDeviceFeatures2(pd, &features2);

  const bool size_control = (api13 || ext_size_control) && size_features.subgroupSizeControl &&
                            size_features.computeFullSubgroups &&
                            (size_props.requiredSubgroupSizeStages & VK_SHADER_STAGE_COMPUTE_BIT);
  c.size_control_core = size_control && api13;
  c.size_control_ext = size_control && !api13;

  DeviceInfo& d = c.info;
  d.name = base.deviceName;
  d.type = type_name(base.deviceType);
  d.driver_name = driver.driverName;
  d.driver_info = driver.driverInfo;
  d.api_version = version_string(base.apiVersion);
  d.vendor_id = base.vendorID;
  d.subgroup_size = props11.subgroupSize;
  d.min_subgroup_size = size_control ? size_props.minSubgroupSize : props11.subgroupSize;
  d.max_subgroup_size = size_control ? size_props.maxSubgroupSize : props11.subgroupSize;
  d.compute_full_subgroups = size_control;
  const bool compute_subgroups = props11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT;
  d.subgroup_ballot =
      compute_subgroups && (props11.subgroupSupportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT);
  d.subgroup_arithmetic =
      compute_subgroups && (props11.subgroupSupportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT);
  d.float_atomic_add = c.atomic_float_ext && atomic_features.shaderBufferFloat32AtomicAdd;
  d.max_storage_buffer_range = base.limits.maxStorageBufferRange;
  d.max_memory_allocation_size = maint3.maxMemoryAllocationSize;
  d.max_push_constants_size = base.limits.maxPushConstantsSize;
  d.max_compute_shared_memory_size = base.limits.maxComputeSharedMemorySize;
  d.max_per_stage_storage_buffers = base.limits.maxPerStageDescriptorStorageBuffers;
  d.max_per_stage_sampled_images = base.limits.maxPerStageDescriptorSampledImages;
  d.max_texel_buffer_elements = base.limits.maxTexelBufferElements;
  d.max_compute_workgroup_invocations = base.limits.maxComputeWorkGroupInvocations;
  for (int i = 0; i < 3; ++i) d.max_compute_workgroup_count[i] = base.limits.maxComputeWorkGroupCount[i];
  d.timestamp_period_ns = base.limits.timestampPeriod;

  if (c.queue_family >= 0) {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
    d.timestamps = families[static_cast<uint32_t>(c.queue_family)].timestampValidBits > 0;
  }

  VkPhysicalDeviceMemoryProperties mem{};
  vkGetPhysicalDeviceMemoryProperties(pd, &mem);
  for (uint32_t i = 0; i < mem.memoryHeapCount; ++i)
    d.memory_heaps.push_back(
        {mem.memoryHeaps[i].size, (mem.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0});
  return c;
}

bool usable(const Candidate& c) {
  return c.api >= VK_API_VERSION_1_2 && c.queue_family >= 0 && c.info.subgroup_ballot &&
         c.info.subgroup_arithmetic;
}

VkInstance create_instance(bool validation, VkDebugUtilsMessengerCreateInfoEXT* messenger_info) {
  uint32_t loader_version = VK_API_VERSION_1_0;
  if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_2)
    throw NoDeviceError(
        "the Vulkan loader supports only Vulkan " + version_string(loader_version) +
        "; the engine needs 1.2 or newer: `apt-get install libvulkan1` from a current release");

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;

  if (validation) {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> available(n);
    vkEnumerateInstanceLayerProperties(&n, available.data());
    const bool found = std::any_of(available.begin(), available.end(), [](const VkLayerProperties& l) {
      return std::strcmp(l.layerName, kValidationLayer) == 0;
    });
    if (!found)
      throw std::runtime_error(
          "LITGS_VALIDATION=1 asks for the Vulkan validation layer, but VK_LAYER_KHRONOS_validation is not "
          "installed: `apt-get install vulkan-validationlayers`");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    features.pNext = messenger_info;
  }

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "litgs-engine";
  app.pEngineName = "litgs";
  app.apiVersion = VK_API_VERSION_1_3;

  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &app;
  ci.enabledLayerCount = static_cast<uint32_t>(layers.size());
  ci.ppEnabledLayerNames = layers.data();
  ci.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  if (validation) ci.pNext = &features;

  VkInstance instance = VK_NULL_HANDLE;
  const VkResult r = vkCreateInstance(&ci, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw NoDeviceError(
        std::string("no Vulkan driver found (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER): ") +
        kInstallHint);
  LITGS_VK_CHECK(r);
  return instance;
}

std::vector<Candidate> enumerate(VkInstance instance) {
  uint32_t n = 0;
  const VkResult r = vkEnumeratePhysicalDevices(instance, &n, nullptr);
  if (r == VK_ERROR_INITIALIZATION_FAILED) return {};
  LITGS_VK_CHECK(r);
  std::vector<VkPhysicalDevice> handles(n);
  LITGS_VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, handles.data()));
  std::vector<Candidate> out;
  for (VkPhysicalDevice pd : handles) {
    Candidate c = describe(pd);
    if (!usable(c)) continue;
    c.info.index = static_cast<uint32_t>(out.size());
    out.push_back(std::move(c));
  }
  return out;
}

const Candidate& choose(const std::vector<Candidate>& candidates, const std::string& selector) {
  if (candidates.empty())
    throw NoDeviceError(
        std::string("no Vulkan 1.2+ device with compute and subgroup ballot/arithmetic found: ") +
        kInstallHint);
  if (!selector.empty()) {
    const bool numeric =
        std::all_of(selector.begin(), selector.end(), [](char ch) { return std::isdigit(ch); });
    if (numeric) {
      const unsigned long idx = std::stoul(selector);
      if (idx >= candidates.size())
        throw NoDeviceError("LITGS_DEVICE=" + selector + " but only " + std::to_string(candidates.size()) +
                            " usable Vulkan device(s) exist (indices 0.." +
                            std::to_string(candidates.size() - 1) + ")");
      return candidates[idx];
    }
    for (const Candidate& c : candidates)
      if (lower(c.info.name).find(lower(selector)) != std::string::npos) return c;
    std::string names;
    for (const Candidate& c : candidates) names += "\n  " + std::to_string(c.info.index) + ": " + c.info.name;
    throw NoDeviceError("LITGS_DEVICE=\"" + selector + "\" matches no device name; usable devices:" + names);
  }
  for (const Candidate& c : candidates)
    if (c.device_type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU) return c;
  return candidates.front();
}

}  // namespace

struct ContextCallbacks {
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                   void* user) {
    auto* ctx = static_cast<Context*>(user);
    const bool is_error = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    ctx->record_validation_message(is_error, data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
  }
};

ContextOptions ContextOptions::from_environment() {
  ContextOptions o;
  if (const char* dev = std::getenv("LITGS_DEVICE")) o.device_selector = dev;
  if (const char* val = std::getenv("LITGS_VALIDATION")) o.validation = std::string(val) == "1";
  return o;
}

void ContextOptions::check() const {
  if (device_selector.find('\0') != std::string::npos)
    throw std::invalid_argument("ContextOptions.device_selector contains a NUL character");
}

Context::Context(const ContextOptions& options) : validation_(options.validation) {
  options.check();
  VkDebugUtilsMessengerCreateInfoEXT messenger_info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger_info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger_info.pfnUserCallback = &ContextCallbacks::on_message;
  messenger_info.pUserData = this;

  instance_ = create_instance(validation_, &messenger_info);
  try {
    if (validation_) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      if (!create)
        throw std::runtime_error("validation requested but vkCreateDebugUtilsMessengerEXT is missing");
      LITGS_VK_CHECK(create(instance_, &messenger_info, nullptr, &messenger_));
    }

    const std::vector<Candidate> candidates = enumerate(instance_);
    const Candidate& chosen = choose(candidates, options.device_selector);
    physical_device_ = chosen.handle;
    info_ = chosen.info;
    queue_family_ = static_cast<uint32_t>(chosen.queue_family);
    vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);

    // Enable only what the kernels use: subgroup size control (radix sort and scan pin one subgroup per
    // workgroup) and float atomics (the rasterizer's backward pass), where present.
    std::vector<const char*> extensions;
    VkPhysicalDeviceFeatures2 features2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceSubgroupSizeControlFeatures size_ext{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES};
    VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomic{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
    void** tail = &features2.pNext;
    if (chosen.size_control_core) {
      features13.subgroupSizeControl = VK_TRUE;
      features13.computeFullSubgroups = VK_TRUE;
      *tail = &features13;
      tail = &features13.pNext;
    } else if (chosen.size_control_ext) {
      extensions.push_back(VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME);
      size_ext.subgroupSizeControl = VK_TRUE;
      size_ext.computeFullSubgroups = VK_TRUE;
      *tail = &size_ext;
      tail = &size_ext.pNext;
    }
    if (info_.float_atomic_add) {
      extensions.push_back(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
      atomic.shaderBufferFloat32AtomicAdd = VK_TRUE;
      *tail = &atomic;
      tail = &atomic.pNext;
    }

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = queue_family_;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pNext = &features2;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &queue_info;
    dci.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    dci.ppEnabledExtensionNames = extensions.data();
    LITGS_VK_CHECK(vkCreateDevice(physical_device_, &dci, nullptr, &device_));
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = queue_family_;
    LITGS_VK_CHECK(vkCreateCommandPool(device_, &pool_info, nullptr, &command_pool_));
    sequence_pools_ = std::make_unique<SequencePools>(device_, command_pool_);
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    LITGS_VK_CHECK(vkCreateFence(device_, &fence_info, nullptr, &one_off_fence_));
  } catch (...) {
    release();
    throw;
  }
}

Context::~Context() {
  release();
}

void Context::release() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    staging_.reset();
    sequence_pools_.reset();
    if (one_off_fence_) vkDestroyFence(device_, one_off_fence_, nullptr);
    if (command_pool_) vkDestroyCommandPool(device_, command_pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
  }
  if (instance_) {
    vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
  }
}

uint32_t Context::find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                                   VkMemoryPropertyFlags preferred) const {
  int fallback = -1;
  for (uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
    if (!(type_bits & (1u << i))) continue;
    const VkMemoryPropertyFlags f = memory_properties_.memoryTypes[i].propertyFlags;
    if ((f & required) != required) continue;
    if ((f & preferred) == preferred) return i;
    if (fallback < 0) fallback = static_cast<int>(i);
  }
  if (fallback < 0) {
    std::ostringstream msg;
    msg << "no Vulkan memory type with flags 0x" << std::hex << required << " for type bits 0x" << type_bits
        << " on " << info_.name;
    throw std::runtime_error(msg.str());
  }
  return static_cast<uint32_t>(fallback);
}

VkMemoryPropertyFlags Context::memory_type_flags(uint32_t type_index) const {
  return memory_properties_.memoryTypes[type_index].propertyFlags;
}

VkCommandBuffer Context::begin_one_off() {
  VkCommandBuffer cmd = sequence_pools_->take_command_buffer();
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  const VkResult r = vkBeginCommandBuffer(cmd, &bi);
  if (r != VK_SUCCESS) {
    sequence_pools_->give_back(cmd);
    LITGS_VK_CHECK(r);
  }
  return cmd;
}

void Context::end_one_off(VkCommandBuffer cmd) {
  struct GiveBack {
    SequencePools* pools;
    VkCommandBuffer cmd;
    ~GiveBack() { pools->give_back(cmd); }
  } give_back_on_exit{sequence_pools_.get(), cmd};
  LITGS_VK_CHECK(vkEndCommandBuffer(cmd));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  LITGS_VK_CHECK(vkResetFences(device_, 1, &one_off_fence_));
  LITGS_VK_CHECK(vkQueueSubmit(queue_, 1, &si, one_off_fence_));
  wait_for_fence(one_off_fence_);
}

void Context::wait_for_fence(VkFence fence) {
  if (info_.type != "cpu") {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
    do {
      const VkResult r = vkGetFenceStatus(device_, fence);
      if (r == VK_SUCCESS) return;
      if (r != VK_NOT_READY) LITGS_VK_CHECK(r);
    } while (std::chrono::steady_clock::now() < give_up);
  }
  LITGS_VK_CHECK(vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX));
}

uint64_t Context::kept_staging_bytes() {
  std::lock_guard<std::mutex> lock(staging_mutex_);
  return staging_ ? staging_->size_bytes() : 0;
}

Buffer& Context::kept_staging(uint64_t bytes) {
  if (bytes > kKeptStagingBytes)
    throw std::logic_error("Context::kept_staging: " + std::to_string(bytes) + " bytes exceed the kept " +
                           std::to_string(kKeptStagingBytes));
  if (!staging_ || staging_->size_bytes() < bytes) {
    staging_.reset();  // before allocating the larger one
    // Grown in steps of 1 MiB so that a few sizes cover every render.
    const uint64_t rounded = (bytes + (1ull << 20) - 1) & ~((1ull << 20) - 1);
    staging_ = std::make_unique<Buffer>(*this, "context: kept staging", rounded, MemoryKind::kHostVisible);
  }
  return *staging_;
}

void Context::record_validation_message(bool is_error, const std::string& message) {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  if (is_error) ++error_count_;
  messages_.push_back((is_error ? "[error] " : "[warning] ") + message);
  std::cerr << "litgs: validation " << (is_error ? "error: " : "warning: ") << message << "\n";
}

size_t Context::validation_error_count() const {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  return error_count_;
}

std::vector<std::string> Context::validation_messages() const {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  return messages_;
}

void Context::clear_validation_messages() {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  messages_.clear();
  error_count_ = 0;
}

std::vector<DeviceInfo> Context::list_devices() {
  VkInstance instance = create_instance(false, nullptr);
  std::vector<DeviceInfo> out;
  try {
    for (const Candidate& c : enumerate(instance)) out.push_back(c.info);
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return out;
}

}  // namespace litgs::engine
