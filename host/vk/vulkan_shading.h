// The Vulkan shading engine: the sorted pipeline's shade stage as compute dispatches.
//
// Per batch slot (two: double buffering) it keeps an input and a result buffer sized to the
// largest batch so far, a command buffer, a fence and a timestamp query pool. submit() records
// one dispatch per non-empty shader range, with {offset, count} in push constants, and returns
// at once; wait() waits on the fence. Meanwhile the renderer loads, traverses and sets up the
// next batch into the other slot. Inputs are written by the hit-setup stage straight into the
// mapped buffer where memory is device-local and host-visible (lavapipe, integrated GPUs,
// resizable BAR); elsewhere the engine records staging copies (host/vk/buffer.h).
//
// Only the kernels the scene needs become pipelines: one per surface model its meshes use
// (sorted shading), or the megakernel alone (unsorted hits); specialisation constants drop
// emission and next-event estimation without emitters, and the per-hit albedo without textures.
#pragma once

#include "host/backend/backend.h"
#include "host/pipeline/shading_engine.h"

#include <memory>

namespace spw {
namespace vk {
class Context;
}

// The context must outlive the engine. Throws VulkanError / std::runtime_error on failure.
std::unique_ptr<ShadingEngine>
makeVulkanShading(const RenderContext& ctx, const PipelineConfig& pipeline, vk::Context& context);

} // namespace spw
