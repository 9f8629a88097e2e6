// The sorted pipeline's knobs that are not in the scene file (ablations and the spill folder).
#pragma once

#include "host/pipeline/ray_sort_mode.h"
#include "host/ray_record.h"

#include <optional>
#include <string>

namespace spw {

// What the scene's settings do not say about the pipeline: the ablation knobs.
struct PipelineConfig {
    RayFormat rayFormat = RayFormat::Compact;
    RaySortMode raySort = RaySortMode::Auto;
    bool hitSort = true;
    std::optional<int> binExponent;         // overrides settings: bin exponent
    std::optional<double> memoryBudgetMiB;  // overrides settings: memory budget
    std::string spillDir;                   // empty: the system temp folder
};

} // namespace spw
