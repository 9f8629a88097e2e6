// The sorted pipeline's knobs that are not in the scene file (ablations and the spill folder).
#pragma once

#include "host/pipeline/ray_sort_mode.h"
#include "host/pipeline/ray_record.h"

#include <optional>
#include <string>

namespace spw {

// How hits are shaded. Sorted: hits sorted by (shader, object, primitive), one homogeneous
// dispatch per shader range, each with its model's own kernel. Megakernel (the ablation): the
// hits stay unsorted and one uber-shader switches on the model per hit. Unsorted hits (also
// --hit-sort off) always take the megakernel: they have no homogeneous ranges.
enum class ShadingMode { Sorted, Megakernel };
ShadingMode parseShadingMode(const std::string& name); // "sorted" | "megakernel"; throws invalid_argument
const char* shadingModeName(ShadingMode mode);

// What the scene's settings do not say about the pipeline: the ablation knobs.
struct PipelineConfig {
    RayFormat rayFormat = RayFormat::Compact;
    RaySortMode raySort = RaySortMode::Auto;
    bool hitSort = true;
    ShadingMode shading = ShadingMode::Sorted;
    // Hits are sorted only for sorted shading.
    bool sortsHits() const { return hitSort && shading == ShadingMode::Sorted; }
    std::optional<int> binExponent;         // overrides settings: bin exponent
    std::optional<double> memoryBudgetMiB;  // overrides settings: memory budget
    std::string spillDir;                   // empty: the system temp folder
};

} // namespace spw
