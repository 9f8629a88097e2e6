// Buffers and their memory. Spillway allocates a handful of long-lived buffers (the scene's
// tables, and per batch slot the inputs and results), so each owns its own allocation: no
// sub-allocator is needed.
//
// HostArray is what the host fills or reads: where the device has memory that is both
// device-local and host-visible (lavapipe, integrated GPUs, resizable BAR) the buffer is mapped
// and written or read in place, no copy at all; elsewhere a device-local buffer is paired with a
// host-visible staging buffer and the engine records the copies. Reads back take only memory
// the host caches: uncached BAR memory is written in place but read through staging.
#pragma once

#include "host/vk/context.h"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <optional>

namespace spw::vk {

// The first memory type allowed by `typeBits` with every `required` flag, preferring one that
// also has every `preferred` flag.
std::optional<uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& memory,
                                       uint32_t typeBits, VkMemoryPropertyFlags required,
                                       VkMemoryPropertyFlags preferred = 0);

// One VkBuffer with its own memory, persistently mapped when host-visible.
class Buffer {
  public:
    // Memory: the first type allowed for the buffer with every `required` flag, preferring one
    // with every `preferred` flag too; throws when none fits.
    Buffer(const Context& context, VkDeviceSize size, VkBufferUsageFlags usage,
           VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred = 0);
    ~Buffer();
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;

    VkBuffer handle() const { return buffer_; }
    VkDeviceSize size() const { return size_; }
    void* mapped() const { return mapped_; } // nullptr unless host-visible
    VkMemoryPropertyFlags flags() const { return flags_; }

  private:
    VkDevice device_;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkDeviceSize size_;
    void* mapped_ = nullptr;
    VkMemoryPropertyFlags flags_ = 0;
};

class HostArray {
  public:
    enum class Direction { Upload, Download };
    // A buffer of `bytes` (at least 16) the host fills (Upload: kernels read it as a uniform texel
    // buffer) or reads (Download: kernels write it as a storage buffer).
    HostArray(const Context& context, VkDeviceSize bytes, Direction direction, bool forceStaging);

    void* host() const { return staging_ ? staging_->mapped() : device_->mapped(); }
    VkBuffer device() const { return device_->handle(); }
    VkDeviceSize size() const { return device_->size(); }
    bool staged() const { return staging_ != nullptr; }
    // Upload: staging -> device; download: device -> staging. Nothing when mapped in place. The
    // caller records the barriers around it.
    void recordCopy(VkCommandBuffer cmd, VkDeviceSize bytes) const;
    // "mapped in place" or "staged"
    const char* mode() const { return staged() ? "staged" : "mapped in place"; }

  private:
    Direction direction_;
    std::unique_ptr<Buffer> device_, staging_;
};

} // namespace spw::vk
