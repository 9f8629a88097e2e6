#include "embree_backend/cutouts.h"

namespace spw {

Cutouts::Cutouts(const Scene& scene, const TextureResolver& textures)
    : scene_(scene), textures_(textures) {
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        meshes_ += filters(uint(m));
}

bool Cutouts::filters(uint mesh) const {
    return scene_.shaders[size_t(scene_.meshes[mesh].shader)].cutout.enabled;
}

bool Cutouts::keeps(uint meshIndex, uint prim, float u, float v) const {
    const Mesh& mesh = scene_.meshes[meshIndex];
    const Cutout& c = scene_.shaders[size_t(mesh.shader)].cutout;
    float alpha = c.alpha;
    if (c.texture >= 0) {
        const vec2 uv = mesh.uvAt(prim, u, v);
        vec3 value;
        textures_.values(c.texture, 1, &uv, nullptr, &value);
        alpha *= value.x;
    }
    return alpha >= c.cutoff;
}

} // namespace spw
