#include "host/scene_view/hit_setup.h"

#include "host/scene_view/hit_triangle.h"
#include "host/scene_view/wide_hits.h"

#include "shared/cone.h"
#include "shared/offset.h"
#include "shared/sampling.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace spw {

HitSetup::HitSetup(const Scene& scene, const SceneLights& lights) : src_(scene), lights_(lights) {
    for (const Mesh& mesh : scene.meshes) {
        anyNormals_ = anyNormals_ || !mesh.normals.empty();
        anyUvs_ = anyUvs_ || !mesh.uvs.empty();
    }
}

namespace {
// Each vertex's tangent plane lifts p onto it where p lies below it: the smooth surface's height
// over triangle c (unit geometric normal ng) at p; 0 without vertex normals.
// Wide twin: smoothLift in host/scene_view/wide_hits.cpp.
template <class Triangle> float liftOver(const Triangle& c, vec3 p, vec3 ng) {
    if (!c.hasNormals()) return 0.0f;
    auto toPlane = [&](int i) {
        const vec3 n = c.n(i);
        return n * std::max(0.0f, glm::dot(c.p(i) - p, n));
    };
    const vec3 up = (1.0f - c.u - c.v) * toPlane(0) + c.u * toPlane(1) + c.v * toPlane(2);
    const float lift = glm::dot(up, ng);
    return std::isfinite(lift) ? lift : 0.0f;
}

// The geometry of a hit on triangle c at distance t: position, normals, offset, lift.
// Wide twin: setUpHitLanes (host/scene_view/wide_hits.cpp).
template <class Triangle> void placeHit(const Triangle& c, float t, SurfaceHit& hit) {
    // References, not copies: GCC copies a 12-byte vec3 through the stack in two stores that one
    // 8-byte load then straddles, a store-forwarding stall that was a quarter of this function.
    const vec3 &p0 = c.p(0), &p1 = c.p(1), &p2 = c.p(2);
    const float u = c.u, v = c.v, w = 1.0f - u - v;
    hit.p = w * p0 + u * p1 + v * p2;
    hit.t = t;
    hit.ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    hit.ns = hit.ng;
    if (c.hasNormals()) {
        vec3 n = w * c.n(0) + u * c.n(1) + v * c.n(2);
        float len = glm::length(n);
        if (len > 0.0f) hit.ns = n / len;
    }
    hit.offset = surfaceOffset(hit.p, p0, p1, p2, hit.ng);
    hit.lift = liftOver(c, hit.p, hit.ng);
}
} // namespace

void HitSetup::surfaceHit(const HitRecord& h, SurfaceHit& hit) const {
    onHitTriangle(src_, h, [&](const auto& c) { placeHit(c, h.t, hit); });
    hit.shader = uint(src_.meshes[h.mesh].shader);
    hit.emitter = lights_.emitterOf(h.instance, h.mesh, h.prim);
    hit.albedo = vec3(0.0f);
    hit.material = 0u;
    hit.extension = uvec2(0u);
}

float HitSetup::smoothLift(const Mesh& mesh, uvec3 tri, float u, float v, vec3 p, vec3 ng) {
    MeshTriangle c(mesh, 0, u, v);
    c.tri = tri;
    return liftOver(c, p, ng);
}

void HitSetup::applyVertexColour(const HitRecord& h, SurfaceHit& hit) const {
    if (src_.meshes[h.mesh].colours.empty()) return;
    onHitTriangle(src_, h, [&](const auto& c) {
        hit.albedo *= (1.0f - c.u - c.v) * c.colour(0) + c.u * c.colour(1) + c.v * c.colour(2);
    });
}

void HitSetup::setUpHit(const HitRecord& h, vec3 dir, uint cone, const TextureResolver& textures,
                        bool albedo, SurfaceHit& hit) const {
    surfaceHit(h, hit);
    if (!albedo) return;
    const Shader& shader = src_.shaders[hit.shader];
    if (!shader.looksUpTextures()) {
        hit.albedo = textures.albedo(shader, vec2(0.0f), 0.0f);
        applyVertexColour(h, hit);
        return;
    }
    vec2 uv;
    float footprint;
    textureQuery(h, dir, cone, hit, uv, footprint);
    hit.albedo = textures.albedo(shader, uv, footprint);
    applyVertexColour(h, hit);
    const HitRecord* record = &h;
    SurfaceHit* out = &hit;
    applyMaps(shader, textures, 1, &uv, &footprint, &record, &out);
}

namespace {
// x in [0, 1] as a 16-bit unsigned normalized integer (shared/bsdf.h's shaderAtHit reads it).
uint unorm16(float x) {
    return uint(std::lround(std::clamp(x, 0.0f, 1.0f) * 65535.0f));
}
} // namespace

void HitSetup::applyMaps(const Shader& shader, const TextureResolver& textures, size_t n,
                         const vec2* uv, const float* footprint, const HitRecord* const* hits,
                         SurfaceHit* const* hit) const {
    if (!shader.hasMaps()) return;
    thread_local std::vector<vec3> texels, interpolated;
    texels.resize(n);
    const bool coatNormal = (shader.params.flags & kShaderCoatNormal) != 0u;
    if (coatNormal) { // the coat's normal map tilts the interpolated normal, not the base's map
        interpolated.resize(n);
        for (size_t k = 0; k < n; ++k)
            interpolated[k] = hit[k]->ns;
    }
    if (shader.normalTexture >= 0) {
        textures.values(shader.normalTexture, n, uv, footprint, texels.data());
        for (size_t k = 0; k < n; ++k)
            hit[k]->ns = tiltedNormal(*hits[k], hit[k]->ns, texels[k], shader.normalScale);
    }
    if (shader.metallicRoughnessTexture >= 0) {
        textures.values(shader.metallicRoughnessTexture, n, uv, footprint, texels.data());
        for (size_t k = 0; k < n; ++k)
            hit[k]->material = unorm16(shader.params.metallic * texels[k].z) |
                               unorm16(shader.roughness * texels[k].y) << 16u;
    }
    if ((shader.params.flags & kShaderHitExtension) != 0u)
        applyExtensionMaps(shader, textures, n, uv, footprint, hit);
    if (!coatNormal) return;
    if (shader.coatNormalTexture >= 0) {
        textures.values(shader.coatNormalTexture, n, uv, footprint, texels.data());
        for (size_t k = 0; k < n; ++k)
            interpolated[k] =
                tiltedNormal(*hits[k], interpolated[k], texels[k], shader.coatNormalScale);
    }
    for (size_t k = 0; k < n; ++k)
        hit[k]->extension.y = packHalf2x16(octahedralEncode(interpolated[k]));
}

void HitSetup::applyExtensionMaps(const Shader& shader, const TextureResolver& textures, size_t n,
                                  const vec2* uv, const float* footprint, SurfaceHit* const* hit) {
    thread_local std::vector<vec4> slots;
    thread_local std::vector<vec3> texels;
    slots.resize(n);
    texels.resize(n);
    for (size_t k = 0; k < n; ++k)
        for (int s = 0; s < 4; ++s)
            slots[k][s] = shader.extension[size_t(s)].factor;
    int looked = -1; // the texture `texels` holds
    for (int s = 0; s < 4; ++s) {
        const Shader::ExtensionMap& m = shader.extension[size_t(s)];
        if (m.texture < 0) continue;
        if (m.texture != looked) textures.values(m.texture, n, uv, footprint, texels.data());
        looked = m.texture;
        for (size_t k = 0; k < n; ++k)
            slots[k][s] *= texels[k][m.component];
    }
    for (size_t k = 0; k < n; ++k)
        hit[k]->extension = uvec2(packHalf2x16(vec2(slots[k].x, slots[k].y)),
                                  packHalf2x16(vec2(slots[k].z, slots[k].w)));
}

namespace {
template <class Triangle> vec3 tiltOn(const Triangle& c, vec3 n, vec3 texel, float scale) {
    if (!c.hasUvs()) return n;
    const vec3 e1 = c.p(1) - c.p(0), e2 = c.p(2) - c.p(0);
    const vec2 d1 = c.uv(1) - c.uv(0), d2 = c.uv(2) - c.uv(0);
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (!(std::fabs(det) > 0.0f)) return n;
    // dp/du and dp/dv of the triangle's texture mapping.
    const vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det, dpdv = (e2 * d1.x - e1 * d2.x) / det;
    const vec3 t = dpdu - n * glm::dot(n, dpdu);
    const float tLength = glm::length(t);
    if (!(tLength > 0.0f) || !std::isfinite(tLength)) return n;
    const vec3 tangent = t / tLength;
    vec3 bitangent = glm::cross(n, tangent);
    if (glm::dot(bitangent, dpdv) < 0.0f) bitangent = -bitangent; // a mirrored mapping
    const vec3 local = (2.0f * texel - 1.0f) * vec3(scale, scale, 1.0f);
    const vec3 tilted = tangent * local.x + bitangent * local.y + n * local.z;
    const float length = glm::length(tilted);
    return length > 0.0f && std::isfinite(length) ? tilted / length : n;
}

// The texture lookup's coordinates on triangle c and its filter width in texture space: the
// cone's width at the hit, stretched by the incidence (1/|cos|, at most 1000x at grazing angles)
// and scaled by the triangle's texture area over its world area (the Delta_0 term of
// Akenine-Moller et al. 2019's ray-cone LOD).
// Wide twin: setUpHitLanes (host/scene_view/wide_hits.cpp), with placeHit.
template <class Triangle>
void queryOn(const Triangle& c, vec3 dir, uint cone, float t, vec3 ng, vec2& uv, float& footprint) {
    footprint = 0.0f;
    if (!c.hasUvs()) {
        uv = vec2(0.0f);
        return;
    }
    const vec3 p0 = c.p(0);
    const vec2 t0 = c.uv(0);
    const float worldArea = glm::length(glm::cross(c.p(1) - p0, c.p(2) - p0));
    const vec2 a = c.uv(1) - t0, b = c.uv(2) - t0;
    const float uvArea = std::fabs(a.x * b.y - a.y * b.x);
    const float cosine = std::max(std::fabs(glm::dot(dir, ng)), 1e-3f);
    if (worldArea > 0.0f) footprint = coneWidthAt(cone, t) / cosine * std::sqrt(uvArea / worldArea);
    uv = (1.0f - c.u - c.v) * c.uv(0) + c.u * c.uv(1) + c.v * c.uv(2);
}
} // namespace

vec3 HitSetup::tiltedNormal(const HitRecord& h, vec3 n, vec3 texel, float scale) const {
    return onHitTriangle(src_, h, [&](const auto& c) { return tiltOn(c, n, texel, scale); });
}

void HitSetup::textureQuery(const HitRecord& h, vec3 dir, uint cone, const SurfaceHit& hit,
                            vec2& uv, float& footprint) const {
    onHitTriangle(src_, h,
                  [&](const auto& c) { queryOn(c, dir, cone, h.t, hit.ng, uv, footprint); });
}

namespace {
void setLane(simd::Vec3s& lanes, size_t j, vec3 v) {
    lanes.x.v[j] = v.x, lanes.y.v[j] = v.y, lanes.z.v[j] = v.z;
}
void setLane(simd::Vec2s& lanes, size_t j, vec2 v) {
    lanes.x.v[j] = v.x, lanes.y.v[j] = v.y;
}
vec3 lane(const simd::Vec3s& lanes, size_t j) {
    return vec3(lanes.x.v[j], lanes.y.v[j], lanes.z.v[j]);
}

// A hit's triangle c, ray and distance t into lane `to` of `l`: vertex normals, and texture
// coordinates with the ray's direction and cone, where the block has any (l.anyNormals,
// l.anyUvs), zeros and a mask of 0 in the lanes of a mesh without them.
template <class Triangle>
void gatherLane(const Triangle& c, float t, vec3 dir, uint cone, HitLanes& l, size_t to) {
    l.u.v[to] = c.u, l.v.v[to] = c.v, l.t.v[to] = t;
    setLane(l.p0, to, c.p(0));
    setLane(l.p1, to, c.p(1));
    setLane(l.p2, to, c.p(2));
    if (l.anyNormals) {
        const bool has = c.hasNormals();
        l.hasNormals.v[to] = has ? ~0u : 0u;
        setLane(l.n0, to, has ? c.n(0) : vec3(0.0f));
        setLane(l.n1, to, has ? c.n(1) : vec3(0.0f));
        setLane(l.n2, to, has ? c.n(2) : vec3(0.0f));
    }
    if (!l.anyUvs) return; // the ray's direction and cone serve only the texture query
    const bool has = c.hasUvs();
    l.hasUvs.v[to] = has ? ~0u : 0u;
    setLane(l.t0, to, has ? c.uv(0) : vec2(0.0f));
    setLane(l.t1, to, has ? c.uv(1) : vec2(0.0f));
    setLane(l.t2, to, has ? c.uv(2) : vec2(0.0f));
    setLane(l.dir, to, dir);
    l.coneWidth.v[to] = coneWidth(cone), l.coneSpread.v[to] = coneSpread(cone);
}
} // namespace

void HitSetup::setUpHits(size_t n, const HitRecord* const* hits, const vec3* dir, const uint* cone,
                         SurfaceHit* const* out, vec2* uv, float* footprint) const {
    HitLanes l;
    l.anyNormals = anyNormals_, l.anyUvs = anyUvs_;
    const size_t count = simd::wholeVectors(n);
    for (size_t j = 0; j < count; ++j) { // padding repeats the last hit
        const size_t from = std::min(j, n - 1);
        const HitRecord& h = *hits[from];
        onHitTriangle(src_, h,
                      [&](const auto& c) { gatherLane(c, h.t, dir[from], cone[from], l, j); });
    }
    setUpHitLanes(count, l);
    for (size_t j = 0; j < n; ++j) {
        const HitRecord& h = *hits[j];
        SurfaceHit& hit = *out[j];
        const Mesh& mesh = src_.meshes[h.mesh];
        hit.p = lane(l.p, j);
        hit.t = h.t;
        hit.ng = lane(l.ng, j);
        hit.shader = uint(mesh.shader);
        hit.ns = lane(l.ns, j);
        hit.emitter = lights_.emitterOf(h.instance, h.mesh, h.prim);
        hit.albedo = vec3(0.0f);
        hit.offset = l.offset.v[j];
        hit.material = 0u;
        hit.extension = uvec2(0u);
        hit.lift = l.lift.v[j];
        uv[j] = vec2(l.uv.x.v[j], l.uv.y.v[j]);
        footprint[j] = l.footprint.v[j];
    }
}

} // namespace spw
