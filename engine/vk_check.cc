#include "engine/vk_check.h"

#include <sstream>

namespace litgs::engine {

const char* to_string(VkResult result) {
  switch (result) {
#define LITGS_CASE(x) \
  case x:             \
    return #x;
    LITGS_CASE(VK_SUCCESS)
    LITGS_CASE(VK_NOT_READY)
    LITGS_CASE(VK_TIMEOUT)
    LITGS_CASE(VK_INCOMPLETE)
    LITGS_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    LITGS_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    LITGS_CASE(VK_ERROR_INITIALIZATION_FAILED)
    LITGS_CASE(VK_ERROR_DEVICE_LOST)
    LITGS_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    LITGS_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    LITGS_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    LITGS_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    LITGS_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    LITGS_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    LITGS_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    LITGS_CASE(VK_ERROR_FRAGMENTED_POOL)
    LITGS_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    LITGS_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    LITGS_CASE(VK_ERROR_UNKNOWN)
#undef LITGS_CASE
    default:
      return "VkResult(unknown)";
  }
}

void throw_vulkan_error(VkResult result, const char* call, const char* file, int line) {
  std::ostringstream msg;
  msg << "Vulkan call failed with " << to_string(result) << " (" << static_cast<int>(result) << "): " << call
      << " at " << file << ":" << line;
  throw VulkanError(msg.str(), result);
}

}  // namespace litgs::engine
