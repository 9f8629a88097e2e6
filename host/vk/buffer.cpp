#include "host/vk/buffer.h"

#include "host/vk/check.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace spw::vk {

std::optional<uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& memory,
                                       uint32_t typeBits, VkMemoryPropertyFlags required,
                                       VkMemoryPropertyFlags preferred) {
    std::optional<uint32_t> fallback;
    for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
        if (!(typeBits & (1u << i))) continue;
        const VkMemoryPropertyFlags f = memory.memoryTypes[i].propertyFlags;
        if ((f & required) != required) continue;
        if ((f & preferred) == preferred) return i;
        if (!fallback) fallback = i;
    }
    return fallback;
}

Buffer::Buffer(const Context& context, VkDeviceSize size, VkBufferUsageFlags usage,
               VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred)
    : device_(context.device()), size_(size) {
    auto info = zeroed<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    SPW_VK_CHECK(vkCreateBuffer(device_, &info, nullptr, &buffer_));
    try {
        VkMemoryRequirements req{};
        vkGetBufferMemoryRequirements(device_, buffer_, &req);
        std::optional<uint32_t> type =
            findMemoryType(context.memory(), req.memoryTypeBits, required, preferred);
        if (!type)
            throw std::runtime_error(
                "no Vulkan memory type with property flags " + std::to_string(required) +
                " (VkMemoryPropertyFlags) for a buffer of " + std::to_string(size) + " bytes");
        flags_ = context.memory().memoryTypes[*type].propertyFlags;
        auto alloc = zeroed<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = *type;
        SPW_VK_CHECK(vkAllocateMemory(device_, &alloc, nullptr, &memory_));
        SPW_VK_CHECK(vkBindBufferMemory(device_, buffer_, memory_, 0));
        if (flags_ & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
            SPW_VK_CHECK(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    } catch (...) {
        if (memory_) vkFreeMemory(device_, memory_, nullptr);
        vkDestroyBuffer(device_, buffer_, nullptr);
        throw;
    }
}

Buffer::~Buffer() {
    if (mapped_) vkUnmapMemory(device_, memory_);
    vkDestroyBuffer(device_, buffer_, nullptr);
    vkFreeMemory(device_, memory_, nullptr);
}

HostArray::HostArray(const Context& context, VkDeviceSize bytes, Direction direction,
                     bool forceStaging)
    : direction_(direction) {
    bytes = std::max<VkDeviceSize>(bytes, 16); // a texel buffer holds at least one RGBA32 texel
    const bool upload = direction == Direction::Upload;
    constexpr VkMemoryPropertyFlags kLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    constexpr VkMemoryPropertyFlags kHost =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    // In place: device-local and host-visible (and, to be read back, host-cached).
    const VkMemoryPropertyFlags inPlace =
        kLocal | kHost | (upload ? 0 : VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    // What the kernels read is bound as uniform texel buffers, what they write as storage buffers
    // (shaders/shade_kernel.glsl says why).
    const VkBufferUsageFlags storage =
        upload ? VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    bool direct = false;
    if (!forceStaging) {
        for (uint32_t i = 0; i < context.memory().memoryTypeCount; ++i)
            direct = direct || (context.memory().memoryTypes[i].propertyFlags & inPlace) == inPlace;
    }
    if (direct) {
        device_ = std::make_unique<Buffer>(context, bytes, storage, inPlace);
        return;
    }
    device_ = std::make_unique<Buffer>(
        context, bytes,
        storage | (upload ? VK_BUFFER_USAGE_TRANSFER_DST_BIT : VK_BUFFER_USAGE_TRANSFER_SRC_BIT), 0,
        kLocal);
    staging_ = std::make_unique<Buffer>(context, bytes,
                                        upload ? VK_BUFFER_USAGE_TRANSFER_SRC_BIT
                                               : VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        kHost, upload ? 0 : VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
}

void HostArray::recordCopy(VkCommandBuffer cmd, VkDeviceSize bytes) const {
    if (!staging_ || bytes == 0) return;
    VkBufferCopy region{0, 0, bytes};
    if (direction_ == Direction::Upload)
        vkCmdCopyBuffer(cmd, staging_->handle(), device_->handle(), 1, &region);
    else
        vkCmdCopyBuffer(cmd, device_->handle(), staging_->handle(), 1, &region);
}

} // namespace spw::vk
