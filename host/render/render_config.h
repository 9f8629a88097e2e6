// Everything about a render that is not the scene: passed explicitly, never global.
#pragma once

#include "host/pipeline/sorted_renderer_config.h"
#include "shared/types.h"

#include <optional>
#include <string>

namespace spw {

// The Vulkan backend's knobs (--device, and what the tests switch on).
struct VulkanConfig {
    std::string device;              // --device: an index into `spillway devices`, or part of a
                                     // device name; empty: the first usable device
    bool validation = false;         // Khronos validation layer + a messenger counting messages
                                     // (also on when SPILLWAY_VK_VALIDATION=1)
    bool forceStaging = false;       // staging copies even where memory is device-local and
                                     // host-visible (tests the path discrete GPUs take)
    std::uint32_t maxGroupsX = 0;    // tests: cap on workgroups per dimension (0: the device's)
    std::uint64_t maxBindingBytes = 0; // tests: cap on a bound buffer range (0: the device's)
};

struct RenderConfig {
    // reference | cpu | vulkan | auto (vulkan where a device exists, else cpu). The library's
    // default stays cpu so that callers that do not ask for a device never initialise Vulkan;
    // the CLI's default is auto.
    std::string backend = "cpu";
    int threads = 0;                    // 0: every core
    std::optional<int> spp;             // overrides sample base and iterations
    std::optional<std::uint32_t> seed;  // overrides settings.seed
    uint strategy = kStrategyMis;       // light/BSDF sampling ablation (tests, benchmarks)
    PipelineConfig pipeline;            // the sorted backends' knobs
    VulkanConfig vulkan;                // the vulkan backend's knobs
    std::optional<double> timeLimitSeconds; // stop after the iteration that crosses it
};

} // namespace spw
