// Vulkan error handling: every call that returns a VkResult goes through SPW_VK_CHECK, which
// throws a VulkanError naming the result, the expression and file:line, in every build type
// (never an assert that vanishes under NDEBUG). The CLI turns it into a message and exit 1.
#pragma once

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace spw::vk {

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" for VK_ERROR_OUT_OF_DEVICE_MEMORY, and so on.
const char* resultName(VkResult result);

class VulkanError : public std::runtime_error {
  public:
    VulkanError(VkResult result, const std::string& message)
        : std::runtime_error(message), result_(result) {}
    VkResult result() const { return result_; }

  private:
    VkResult result_;
};

// A zeroed Vulkan struct with its sType set (the aggregate `VkX x{sType}` warns under -Wextra).
template <class T> T zeroed(VkStructureType type) {
    T value{};
    value.sType = type;
    return value;
}

[[noreturn]] void throwVulkanError(VkResult result, const char* expression, const char* file,
                                   int line);

inline void check(VkResult result, const char* expression, const char* file, int line) {
    if (result != VK_SUCCESS) throwVulkanError(result, expression, file, line);
}

} // namespace spw::vk

#define SPW_VK_CHECK(expr) ::spw::vk::check((expr), #expr, __FILE__, __LINE__)
