// Hit setup, the same on every backend: from a closest hit (mesh, triangle, barycentrics,
// distance) to the world-space SurfaceHit shading reads — position, normals, self-intersection
// offset, shader, emitter — and the albedo the shader's texture gives there. It reads the scene
// and the emitter table only; the BVH that found the hit is embree_backend/'s.
#pragma once

#include "host/scene/scene.h"
#include "host/scene_view/lights.h"
#include "host/textures/textures.h"

namespace spw {

// A closest hit in Spillway's terms, what traversal hands the rest of the renderer: the mesh
// (Embree's geometry id), the triangle, Embree's barycentric u and v, the distance, and the
// instance that placed the mesh (Scene::instances), or kNoInstance for a world-space mesh.
constexpr uint kNoHit = 0xFFFFFFFFu;
struct HitRecord {
    uint mesh; // kNoHit: the ray missed
    uint prim;
    float u, v, t;
    uint instance = kNoInstance;
};

class HitSetup {
  public:
    // `lights` gives each hit its emitter index; both must outlive this.
    HitSetup(const Scene& scene, const SceneLights& lights);

    // The whole hit. `dir` and `cone`: the ray's unit direction and packed cone
    // (shared/cone.h), for the texture filter width. `albedo` false: the hit ends its path (max
    // depth), so shading never reads the albedo, and no texture is looked up for it (albedo
    // left 0). Written into `hit` in place: a returned 72-byte struct is copied through the
    // stack, which stalls.
    void setUpHit(const HitRecord& h, vec3 dir, uint cone, const TextureResolver& textures,
                  bool albedo, SurfaceHit& hit) const;
    // setUpHit in two halves, for a caller that looks textures up for many hits at once
    // (TextureResolver::albedos): the world-space hit, albedo 0; then where the hit's texture
    // is looked up, its uv and its filter footprint in texture space.
    void setUpGeometry(const HitRecord& h, SurfaceHit& hit) const { surfaceHit(h, hit); }
    void textureQuery(const HitRecord& h, vec3 dir, uint cone, const SurfaceHit& hit, vec2& uv,
                      float& footprint) const;
    // setUpGeometry and textureQuery for n <= simd::kBlock hits at once, the arithmetic SIMD-wide
    // (wide_hits.h), the same bits: *hits[j], reached along a ray of unit direction dir[j] and
    // packed cone cone[j], into *out[j] (albedo 0), its texture coordinates and footprint into
    // uv[j] and footprint[j].
    void setUpHits(size_t n, const HitRecord* const* hits, const vec3* dir, const uint* cone,
                   SurfaceHit* const* out, vec2* uv, float* footprint) const;
    // Unit normal n at hit h tilted by a tangent-space normal map's value `texel` (linear,
    // [0, 1] per channel): to (2 texel - 1), its x and y times `scale`, in the frame the
    // triangle's texture coordinates make (x: growing u, y: growing v), made orthonormal about n
    // (Gram-Schmidt), z along it. n itself where the triangle has no texture frame or the tilted
    // normal is degenerate.
    vec3 tiltedNormal(const HitRecord& h, vec3 n, vec3 texel, float scale) const;
    // What a shader's maps beyond its colour give n hits of it at uv[k] (footprints as
    // albedos()): its normal map's tilt, its metallic-roughness image's SurfaceHit::material,
    // its extension maps' SurfaceHit::extension, and the coat's own normal (kShaderCoatNormal).
    // hits[k] is the closest hit hit[k] was set up from.
    void applyMaps(const Shader& shader, const TextureResolver& textures, size_t n, const vec2* uv,
                   const float* footprint, const HitRecord* const* hits,
                   SurfaceHit* const* hit) const;
    // Shader::extension's four values at n hits into their SurfaceHit::extension.
    static void applyExtensionMaps(const Shader& shader, const TextureResolver& textures, size_t n,
                                   const vec2* uv, const float* footprint, SurfaceHit* const* hit);
    // The albedo times the hit's interpolated vertex colour, where its mesh has them
    // (Mesh::colours). After the albedo is set.
    void applyVertexColour(const HitRecord& h, SurfaceHit& hit) const;
    // What setUpGeometry will read, asked for ahead by a caller that knows many hits before it
    // sets them up: first the triangle's vertex indices, then (reading those) its vertices and
    // vertex normals. On a mesh larger than the caches each is a miss that the depth-first
    // tracer waits for one at a time.
    void prefetchTriangle(const HitRecord& h) const {
        __builtin_prefetch(&src_.meshes[h.mesh].triangles[h.prim]);
    }
    void prefetchVertices(const HitRecord& h) const {
        const Mesh& mesh = src_.meshes[h.mesh];
        const uvec3 tri = mesh.triangles[h.prim];
        for (uint i : {tri.x, tri.y, tri.z}) {
            __builtin_prefetch(&mesh.positions[i]);
            if (!mesh.normals.empty()) __builtin_prefetch(&mesh.normals[i]);
            if (!mesh.uvs.empty()) __builtin_prefetch(&mesh.uvs[i]);
        }
    }

    // SurfaceHit::lift at p, barycentrics (u, v) of triangle `tri` (unit geometric normal ng):
    // the smooth surface's height over the triangle (shared/offset.h's shadowLift), 0 where the
    // mesh has no vertex normals.
    static float smoothLift(const Mesh& mesh, uvec3 tri, float u, float v, vec3 p, vec3 ng);

  private:
    // World-space hit for h (its instance's transform applied); albedo left at 0.
    void surfaceHit(const HitRecord& h, SurfaceHit& hit) const;

    const Scene& src_;
    const SceneLights& lights_;
    // Whether any mesh has vertex normals, texture coordinates: setUpHits skips what none has.
    bool anyNormals_ = false, anyUvs_ = false;
};

} // namespace spw
