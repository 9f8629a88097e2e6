// The reference backend: a plain depth-first path tracer. One task per camera tile; each sample's
// path is traced to its end before the next starts. No batches, no sorting: the simplest correct
// renderer, kept simple on purpose, against which the sorted backends are measured. Its bounce
// arithmetic is shared/path.h's shadeSurface(), the same function the sorted backends run.
#pragma once

#include "host/backend/backend.h"

namespace spw {

class ReferenceRenderer : public Backend {
  public:
    explicit ReferenceRenderer(const RenderContext& ctx) : ctx_(ctx) {}
    bool renderIteration(uint iteration, Film& film) override;

  private:
    RenderContext ctx_;
};

} // namespace spw
