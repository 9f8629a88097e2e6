// Which renderer a render runs on, decided once before anything is built: the user's --backend
// with `auto` resolved, the Vulkan device opened where one is used, and why.
#pragma once

#include "host/backend/render_config.h"

#include <memory>
#include <string>

namespace spw {

namespace vk {
class Context;
}

struct BackendChoice {
    BackendKind kind = BackendKind::Cpu; // Cpu, Vulkan or Reference: never Auto
    std::unique_ptr<vk::Context> vulkan; // the device, for Vulkan
    std::string device;                  // the device's name; the CPU's where none is used
    std::string autoWhy;                 // what `auto` took and why ("" unless asked for auto)
    std::string fallbackWhy;             // why a Vulkan device asked for was not usable, or ""
    BackendChoice();
    BackendChoice(BackendChoice&&) noexcept;
    BackendChoice& operator=(BackendChoice&&) noexcept;
    ~BackendChoice();
};

// Vulkan only when asked for (vulkan, or auto): never for cpu or reference. `auto` takes a real
// GPU, or the device --device names, or lavapipe when the driver variables ask for it
// (vk::chooseAutoDevice), and otherwise renders on cpu. Throws std::runtime_error where
// `--backend vulkan` finds no device.
BackendChoice resolveBackend(const RenderConfig& config);

// The CPU's model name, for --stats' `device`.
std::string cpuName();

} // namespace spw
