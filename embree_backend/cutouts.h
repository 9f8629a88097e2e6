// Alpha cut-outs (Shader::cutout, glTF's alphaMode MASK) as the BVH's hit filter: a hit on a
// mesh whose shader has one is kept where the shader's alpha there is at least its cutoff. The
// alpha is looked up at the finest MIP level (a ray's cone is not known during traversal), so
// the holes a ray sees do not depend on how far it has come. Emission and light sampling ignore
// the holes: a cut-out emitter emits over its whole area.
#pragma once

#include "embree_backend/embree_scene.h"
#include "host/scene/scene.h"
#include "host/textures/textures.h"

#include <vector>

namespace spw {

class Cutouts final : public HitFilter {
  public:
    // Both must outlive this.
    Cutouts(const Scene& scene, const TextureResolver& textures);
    // The meshes with holes.
    int meshes() const { return meshes_; }
    bool filters(uint mesh) const override;
    bool keeps(uint mesh, uint prim, float u, float v) const override;

  private:
    const Scene& scene_;
    const TextureResolver& textures_;
    int meshes_ = 0;
};

} // namespace spw
