// The Vulkan instance, the chosen physical device, its logical device and one compute queue.
// Created only for --backend vulkan or auto (never for cpu or reference), destroyed with the
// render. With `validation`, the Khronos validation layer is enabled and a debug messenger
// prints and counts every warning or error it reports (the tests fail on any).
#pragma once

#include "host/backend/render_config.h"

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace spw::vk {

// No usable Vulkan device at all: no loader-visible driver, no device, or none that qualifies.
// `auto` falls back to cpu on this error only; --backend vulkan exits 1 with its message.
class NoDeviceError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

struct DeviceInfo {
    uint32_t index = 0;
    std::string name;   // "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string type;   // discrete gpu | integrated gpu | virtual gpu | cpu | other
    std::string driver; // "llvmpipe: Mesa 22.3.6 (LLVM 15.0.6)"
    std::string api;    // "1.3.230"
    bool usable = false;
    std::string whyNot; // empty when usable
};

// Every physical device the loader sees, usable or not. Throws NoDeviceError when no instance
// can be made (no driver at all).
std::vector<DeviceInfo> listDevices();

// What `--backend auto` renders with: a real GPU when one is usable (the first discrete one, else
// the first integrated one); a software device (lavapipe) only when the user pointed the loader
// at drivers (`softwareAllowed`: VK_DRIVER_FILES, VK_ICD_FILENAMES or VK_ADD_DRIVER_FILES set),
// since on the same cores it emulates a GPU more slowly than the cpu backend shades; else none,
// and auto renders on cpu. `why` says which and why, in a line for `spillway devices`.
struct AutoChoice {
    int device = -1; // index into the listing, or -1: the cpu backend
    std::string why;
};
AutoChoice chooseAutoDevice(const std::vector<DeviceInfo>& devices, bool softwareAllowed);
// Whether the environment names Vulkan drivers (the variables above).
bool driverVariablesSet();

// The device files through which a GPU driver reaches a GPU under `root` (/dev): DRM's render
// and card nodes (dri/renderD*, dri/card*: Mesa's, AMD's, Intel's, virtio's drivers), NVIDIA's
// (nvidia0..., nvidiactl), WSL's dxg, Qualcomm's kgsl-3d0 and Arm's mali*. None: no Vulkan
// driver on this machine can reach a GPU, whatever drivers are installed (Mesa installs Intel's
// and AMD's beside lavapipe).
std::vector<std::string> gpuDeviceFiles(const std::string& root = "/dev");
// --backend auto's choice where it can be made without starting the loader, which loads every
// installed driver (30-130 ms of a render's start with Mesa's): no driver variable set and no GPU
// device file, so the cpu backend. Empty where the devices must be listed to choose.
std::optional<AutoChoice> autoChoiceWithoutLoader();

// Total warnings and errors the validation messengers of this process have reported (tests
// read it after a render, when the instance and its messenger are gone).
std::uint64_t validationMessageCount();

class Context {
  public:
    // Picks config.device (an index or part of a name) or the first usable device. Throws
    // NoDeviceError when there is none, std::runtime_error when the named one does not exist
    // or is unusable, VulkanError on a failed call.
    explicit Context(const VulkanConfig& config);
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    VkDevice device() const { return device_; }
    VkPhysicalDevice physicalDevice() const { return physical_; }
    VkQueue queue() const { return queue_; }
    uint32_t queueFamily() const { return queueFamily_; }
    const VkPhysicalDeviceProperties& properties() const { return properties_; }
    const VkPhysicalDeviceMemoryProperties& memory() const { return memory_; }
    const DeviceInfo& info() const { return info_; }
    // Nanoseconds per timestamp tick, or 0 when the queue cannot write timestamps.
    double timestampPeriodNs() const { return timestampPeriodNs_; }
    bool validation() const { return validation_; }
    // Warnings and errors the validation layer reported for this context so far.
    std::uint64_t validationMessages() const { return messages_.load(); }

  private:
    void release();

    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    uint32_t queueFamily_ = 0;
    VkPhysicalDeviceProperties properties_{};
    VkPhysicalDeviceMemoryProperties memory_{};
    DeviceInfo info_;
    double timestampPeriodNs_ = 0.0;
    bool validation_ = false;
    std::atomic<std::uint64_t> messages_{0};
};

} // namespace spw::vk
