#include "host/vk/check.h"

namespace spw::vk {

const char* resultName(VkResult result) {
    switch (result) {
#define SPW_RESULT(name)                                                                           \
    case name:                                                                                     \
        return #name;
        SPW_RESULT(VK_SUCCESS)
        SPW_RESULT(VK_NOT_READY)
        SPW_RESULT(VK_TIMEOUT)
        SPW_RESULT(VK_EVENT_SET)
        SPW_RESULT(VK_EVENT_RESET)
        SPW_RESULT(VK_INCOMPLETE)
        SPW_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        SPW_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        SPW_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        SPW_RESULT(VK_ERROR_DEVICE_LOST)
        SPW_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        SPW_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        SPW_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        SPW_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        SPW_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        SPW_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        SPW_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        SPW_RESULT(VK_ERROR_FRAGMENTED_POOL)
        SPW_RESULT(VK_ERROR_UNKNOWN)
        SPW_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        SPW_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        SPW_RESULT(VK_ERROR_FRAGMENTATION)
        SPW_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        SPW_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
#undef SPW_RESULT
    default:
        return "VkResult (unnamed)";
    }
}

void throwVulkanError(VkResult result, const char* expression, const char* file, int line) {
    throw VulkanError(result, std::string(resultName(result)) + " (" + std::to_string(int(result)) +
                                  ") from " + expression + " at " + file + ":" +
                                  std::to_string(line));
}

} // namespace spw::vk
