// Alpha cut-outs (Shader::cutout) as the BVH's hit filter: a hit on a mesh whose shader has one
// is kept where the shader's alpha there is at least its cutoff (glTF's alphaMode MASK), or, for
// a stochastic one (BLEND), with probability alpha: a hash of the ray and the triangle decides,
// so every ray that meets the surface sees it with probability alpha and passes with 1 - alpha,
// and the expected image is the blend, unbiased, as Cycles renders it. The alpha is looked up at
// the finest MIP level (a ray's cone is not known during traversal), so the holes a ray sees do
// not depend on how far it has come. Emission and light sampling ignore the holes: a cut-out
// emitter emits over its whole area.
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
    bool keeps(uint mesh, uint prim, float u, float v, vec3 org, vec3 dir) const override;
    // The number in [0, 1) a stochastic cut-out compares with its alpha for the ray from `org`
    // along `dir` meeting triangle `prim` of `mesh`: a hash of them all, the same every time.
    static float stochasticNumber(uint mesh, uint prim, vec3 org, vec3 dir);

  private:
    const Scene& scene_;
    const TextureResolver& textures_;
    int meshes_ = 0;
};

} // namespace spw
