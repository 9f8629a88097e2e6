// The C++ shading engine: the same shadeSurface() the Vulkan kernels run (the hits of each model
// with a SIMD twin in SIMD registers, simd_shading.h), on the host's threads: fused with the
// other per-hit stages chunk by chunk (stages.h: shadeFused), or, with --stages separate, in TBB
// tasks of `shading size` hits through one slot (TBB already keeps every core busy: nothing to
// overlap).
#pragma once

#include "host/backend/backend.h"
#include "host/pipeline/shading_engine.h"

#include <memory>

namespace spw {

std::unique_ptr<ShadingEngine> makeCpuShading(const RenderContext& ctx);

// Whether the cpu engine (and the fused stages) shade hits SIMD-wide (PipelineConfig::simdShading;
// every scene can).
bool usesSimdShading(const RenderContext& ctx);

} // namespace spw
