// Vulkan result checks that are never compiled out.
#pragma once

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace litgs::engine {

// A Vulkan call failed; what() names the call, the result and the source location.
class VulkanError : public std::runtime_error {
 public:
  VulkanError(const std::string& what, VkResult result) : std::runtime_error(what), result_(result) {}
  VkResult result() const { return result_; }

 private:
  VkResult result_;
};

// No Vulkan loader, driver or suitable device: what() says what is missing and how to install it.
class NoDeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

const char* to_string(VkResult result);

[[noreturn]] void throw_vulkan_error(VkResult result, const char* call, const char* file, int line);

}  // namespace litgs::engine

#define LITGS_VK_CHECK(call)                                                            \
  do {                                                                                  \
    const VkResult litgs_vk_result_ = (call);                                           \
    if (litgs_vk_result_ != VK_SUCCESS)                                                 \
      ::litgs::engine::throw_vulkan_error(litgs_vk_result_, #call, __FILE__, __LINE__); \
  } while (0)
