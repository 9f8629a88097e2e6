// The scene model's few functions: what its types answer about themselves, and the rules that
// every loader applies to what a file says (how far from the camera a scene may reach, how a
// number is written in a message).
#include "host/scene/scene.h"

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace spw {

std::string formatNumber(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    std::string s = std::to_string(v);
    if (std::fabs(v) >= 1e7 || (v != 0 && std::fabs(v) < 1e-4)) {
        // 1e+20 -> 1e20, 1e-05 -> 1e-5: as the format's ranges are written.
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", v);
        std::string g = buf;
        const size_t e = g.find('e');
        if (e == std::string::npos) return g;
        std::string mant = g.substr(0, e), exp = g.substr(e + 1);
        const bool neg = exp[0] == '-';
        exp.erase(0, exp.find_first_not_of("+-0"));
        return mant + "e" + (neg ? "-" : "") + (exp.empty() ? "0" : exp);
    }
    s.erase(s.find_last_not_of('0') + 1);
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
}

std::string beyondReach(const glm::dvec3& p, const std::string& what) {
    const double far = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    if (far <= kMaxDistance) return "";
    return what + " lies " + formatNumber(far) +
           " units from the camera; Spillway renders within " + formatNumber(kMaxDistance) +
           " units of it";
}

float Camera::tanHalfFovX() const {
    if (fovDegrees) return std::tan(glm::radians(*fovDegrees) * 0.5f);
    return 0.5f * filmWidth / focalLength;
}

const char* samplerName(SamplerType s) {
    switch (s) {
    case SamplerType::Independent:
        return "Independent";
    case SamplerType::Grid:
        return "Grid";
    case SamplerType::Stratified:
        return "Stratified";
    case SamplerType::Sobol:
        return "Sobol";
    }
    return "?";
}

std::optional<SamplerType> parseSampler(const std::string& name) {
    for (SamplerType s :
         {SamplerType::Independent, SamplerType::Grid, SamplerType::Stratified, SamplerType::Sobol})
        if (name == samplerName(s)) return s;
    return std::nullopt;
}

namespace {
// The eight corners of the box [lo, hi], moved by `m`, into the bounds [blo, bhi].
void includeBox(const glm::dmat4& m, vec3 lo, vec3 hi, glm::dvec3& blo, glm::dvec3& bhi) {
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        const glm::dvec3 p = glm::dvec3(m * glm::dvec4(corner, 1.0));
        blo = glm::min(blo, p);
        bhi = glm::max(bhi, p);
    }
}
} // namespace

size_t emissiveTriangles(const Scene& scene, const Prototype& proto) {
    size_t n = 0;
    for (uint m : proto.meshes)
        if (scene.shaders[size_t(scene.meshes[m].shader)].params.emission != vec3(0.0f))
            n += scene.meshes[m].triangles.size();
    return n;
}

Instance makeInstance(const Prototype& proto, uint prototype, const glm::dmat4& toWorld,
                      std::string& error) {
    Instance inst;
    inst.prototype = prototype;
    error.clear();
    const glm::dmat3 linear(toWorld);
    const double det = glm::determinant(linear);
    // Singular to double's precision: its normals have no inverse transpose.
    const double scale =
        std::max({glm::length(linear[0]), glm::length(linear[1]), glm::length(linear[2])});
    if (!std::isfinite(det) || !(std::fabs(det) > 1e-12 * scale * scale * scale)) {
        error = "the transform is singular (it flattens the mesh)";
        return inst;
    }
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(toWorld[c][r])) {
                error = "the transform is not finite";
                return inst;
            }
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    includeBox(toWorld, proto.lo, proto.hi, lo, hi);
    for (const glm::dvec3& p : {lo, hi})
        if (std::string far = beyondReach(p, "an instance of " + proto.name); !far.empty()) {
            error = far;
            return inst;
        }
    inst.toWorld = mat4(toWorld);
    inst.normalToWorld = mat3(glm::inverseTranspose(linear));
    inst.mirrors = det < 0.0;
    return inst;
}

void sceneBounds(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi) {
    lo = glm::dvec3(std::numeric_limits<double>::max());
    hi = glm::dvec3(-std::numeric_limits<double>::max());
    for (const Mesh& m : scene.meshes) {
        if (m.prototype >= 0) continue;
        for (const vec3& p : m.positions) {
            lo = glm::min(lo, glm::dvec3(p));
            hi = glm::max(hi, glm::dvec3(p));
        }
    }
    for (const Instance& inst : scene.instances) {
        const Prototype& proto = scene.prototypes[inst.prototype];
        includeBox(glm::dmat4(inst.toWorld), proto.lo, proto.hi, lo, hi);
    }
}

double Scene::renderedTriangles() const {
    std::vector<double> perPrototype(prototypes.size(), 0.0);
    double n = 0.0;
    for (const Mesh& m : meshes)
        (m.prototype >= 0 ? perPrototype[size_t(m.prototype)] : n) += double(m.triangles.size());
    for (const Instance& inst : instances)
        n += perPrototype[inst.prototype];
    return n;
}

bool Scene::usesTextures() const {
    for (const Shader& s : shaders)
        if (s.texture >= 0) return true;
    return false;
}

} // namespace spw
