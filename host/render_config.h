// Everything about a render that is not the scene: passed explicitly, never global.
#pragma once

#include "host/pipeline/sorted_renderer_config.h"
#include "shared/types.h"

#include <optional>
#include <string>

namespace spw {

struct RenderConfig {
    std::string backend = "cpu";       // reference | cpu
    int threads = 0;                    // 0: every core
    std::optional<int> spp;             // overrides sample base and iterations
    std::optional<std::uint32_t> seed;  // overrides settings.seed
    uint strategy = kStrategyMis;       // light/BSDF sampling ablation (tests, benchmarks)
    PipelineConfig pipeline;            // the sorted backends' knobs
};

} // namespace spw
