// The triangle a closest hit lies on, as hit setup reads it: its corners' positions, vertex
// normals, texture coordinates and colours, and the barycentrics (u, v) that interpolate them
// (corner 0 weighs 1 - u - v). Hit setup's arithmetic is written once over either kind:
// - MeshTriangle, a world-space mesh's triangle, read in place from the mesh's arrays;
// - PlacedTriangle, an instanced mesh's triangle moved to world space as a flattened copy of the
//   mesh would hold it: positions by the instance's transform, vertex normals by its inverse
//   transpose (normalised), and, where the transform mirrors, corners 1 and 2 swapped with u and
//   v, the winding a copy takes (the loaders turn a mirrored copy's triangles the same way).
// Internal to host/scene_view/.
#pragma once

#include "host/scene/scene.h"
#include "host/scene_view/hit_setup.h"

#include <glm/geometric.hpp>

namespace spw {

struct MeshTriangle {
    const Mesh& mesh;
    uvec3 tri;
    float u, v;

    MeshTriangle(const Mesh& m, uint prim, float bu, float bv)
        : mesh(m), tri(m.triangles[prim]), u(bu), v(bv) {}
    const vec3& p(int i) const { return mesh.positions[tri[i]]; }
    bool hasNormals() const { return !mesh.normals.empty(); }
    const vec3& n(int i) const { return mesh.normals[tri[i]]; }
    bool hasUvs() const { return !mesh.uvs.empty(); }
    const vec2& uv(int i) const { return mesh.uvs[tri[i]]; }
    bool hasColours() const { return !mesh.colours.empty(); }
    const vec3& colour(int i) const { return mesh.colours[tri[i]]; }
};

class PlacedTriangle {
  public:
    const Mesh& mesh;
    uvec3 tri; // the mesh's vertex indices, in the copy's order
    float u, v;

    PlacedTriangle(const Mesh& m, const Instance& inst, uint prim, float bu, float bv)
        : mesh(m), tri(m.triangles[prim]), u(bu), v(bv) {
        if (inst.mirrors) {
            std::swap(tri.y, tri.z);
            std::swap(u, v);
        }
        for (int i = 0; i < 3; ++i) {
            p_[i] = vec3(inst.toWorld * vec4(mesh.positions[tri[i]], 1.0f));
            if (hasNormals()) n_[i] = glm::normalize(inst.normalToWorld * mesh.normals[tri[i]]);
        }
    }
    const vec3& p(int i) const { return p_[i]; }
    bool hasNormals() const { return !mesh.normals.empty(); }
    const vec3& n(int i) const { return n_[i]; }
    bool hasUvs() const { return !mesh.uvs.empty(); }
    const vec2& uv(int i) const { return mesh.uvs[tri[i]]; }
    bool hasColours() const { return !mesh.colours.empty(); }
    const vec3& colour(int i) const { return mesh.colours[tri[i]]; }

  private:
    vec3 p_[3], n_[3];
};

// f(triangle) for hit h's triangle in `scene`, of the kind its placement makes.
template <class F> decltype(auto) onHitTriangle(const Scene& scene, const HitRecord& h, F&& f) {
    const Mesh& m = scene.meshes[h.mesh];
    if (h.instance == kNoInstance) return f(MeshTriangle(m, h.prim, h.u, h.v));
    return f(PlacedTriangle(m, scene.instances[h.instance], h.prim, h.u, h.v));
}

} // namespace spw
