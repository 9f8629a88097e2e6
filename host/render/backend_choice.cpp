#include "host/render/backend_choice.h"

#include "host/vk/context.h"

#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace spw {

BackendChoice::BackendChoice() = default;
BackendChoice::BackendChoice(BackendChoice&&) noexcept = default;
BackendChoice& BackendChoice::operator=(BackendChoice&&) noexcept = default;
BackendChoice::~BackendChoice() = default;

std::string cpuName() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            auto p = line.find(':');
            if (p != std::string::npos) return line.substr(line.find_first_not_of(" \t", p + 1));
        }
    return "unknown CPU";
}

BackendChoice resolveBackend(const RenderConfig& config) {
    BackendChoice choice;
    choice.kind = config.backend;
    choice.device = cpuName();
    if (config.backend != BackendKind::Vulkan && config.backend != BackendKind::Auto) return choice;
    VulkanConfig vkConfig = config.vulkan;
    bool wanted = config.backend == BackendKind::Vulkan || !vkConfig.device.empty();
    try {
        if (!wanted) {
            const std::optional<vk::AutoChoice> known = vk::autoChoiceWithoutLoader();
            const vk::AutoChoice automatic =
                known ? *known : vk::chooseAutoDevice(vk::listDevices(), vk::driverVariablesSet());
            choice.autoWhy = automatic.why;
            choice.kind = BackendKind::Cpu;
            if (automatic.device >= 0) {
                vkConfig.device = std::to_string(automatic.device);
                wanted = true;
            }
        }
        if (wanted) {
            choice.vulkan = std::make_unique<vk::Context>(vkConfig);
            choice.kind = BackendKind::Vulkan;
            choice.device = choice.vulkan->info().name;
        }
    } catch (const vk::NoDeviceError& e) {
        if (config.backend == BackendKind::Vulkan)
            throw std::runtime_error(std::string("--backend vulkan: ") + e.what());
        // The user asked for Vulkan (--device, or the driver variables) and has none.
        if (wanted || vk::driverVariablesSet())
            std::fprintf(stderr, "spillway: no Vulkan device (%s); rendering on cpu\n", e.what());
        choice.kind = BackendKind::Cpu;
        choice.fallbackWhy = e.what();
    }
    return choice;
}

} // namespace spw
