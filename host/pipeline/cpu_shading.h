// The C++ shading engine: the same shadeSurface() the Vulkan kernels run, in TBB tasks of
// `shading size` hits, shaded at submit in one slot (TBB already keeps every core busy, so there
// is nothing to overlap).
#pragma once

#include "host/backend/backend.h"
#include "host/pipeline/shading_engine.h"

#include <memory>

namespace spw {

std::unique_ptr<ShadingEngine> makeCpuShading(const RenderContext& ctx);

} // namespace spw
