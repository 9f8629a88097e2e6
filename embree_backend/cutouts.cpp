#include "embree_backend/cutouts.h"

#include "shared/rng.h"

namespace spw {

Cutouts::Cutouts(const Scene& scene, const TextureResolver& textures)
    : scene_(scene), textures_(textures) {
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        meshes_ += filters(uint(m));
}

bool Cutouts::filters(uint mesh) const {
    return scene_.shaders[size_t(scene_.meshes[mesh].shader)].cutout.enabled;
}

float Cutouts::stochasticNumber(uint mesh, uint prim, vec3 org, vec3 dir) {
    const uvec4 a = pcg4d(uvec4(floatBitsToUint(org.x), floatBitsToUint(org.y),
                                floatBitsToUint(org.z), floatBitsToUint(dir.x)));
    const uvec4 b = pcg4d(
        uvec4(floatBitsToUint(dir.y) ^ a.x, floatBitsToUint(dir.z) ^ a.y, prim ^ a.z, mesh ^ a.w));
    return uintToUnit(b.x);
}

bool Cutouts::keeps(uint meshIndex, uint prim, float u, float v, vec3 org, vec3 dir) const {
    const Mesh& mesh = scene_.meshes[meshIndex];
    const Cutout& c = scene_.shaders[size_t(mesh.shader)].cutout;
    float alpha = c.alpha;
    if (c.texture >= 0) {
        const vec2 uv = mesh.uvAt(prim, u, v);
        vec3 value;
        textures_.values(c.texture, 1, &uv, nullptr, &value);
        alpha *= value.x;
    }
    if (c.stochastic) return stochasticNumber(meshIndex, prim, org, dir) < alpha;
    return alpha >= c.cutoff;
}

} // namespace spw
