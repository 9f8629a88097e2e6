#include "host/scene/lights.h"

#include "shared/sampling.h"

#include <algorithm>

namespace spw {

SceneLights::SceneLights(const Scene& scene) {
    for (const Shader& s : scene.shaders)
        shaders_.push_back(s.params);

    emitterBase_.assign(scene.meshes.size(), -1);
    double totalPower = 0.0;
    std::vector<double> powers; // per emitter, normalised into pickPdf below
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const ShaderParams& sp = shaders_[size_t(mesh.shader)];
        if (maxComponent(sp.emission) <= 0.0f) continue;
        brightest_ = std::max(brightest_, maxComponent(sp.emission));
        emitterBase_[m] = int(emitters_.size());
        bool twoSided = (sp.flags & kShaderTwoSided) != 0;
        for (const uvec3& t : mesh.triangles) {
            Emitter e{};
            e.p0 = mesh.positions[t.x];
            e.e1 = mesh.positions[t.y] - e.p0;
            e.e2 = mesh.positions[t.z] - e.p0;
            vec3 c = glm::cross(e.e1, e.e2);
            e.area = 0.5f * glm::length(c);
            e.normal = glm::normalize(c);
            e.twoSided = twoSided ? 1u : 0u;
            e.radiance = sp.emission;
            // Power = L * area * pi per emitting side.
            // In double: radiance (up to 1e20) times area can pass float's range.
            const double power =
                double(luminance(sp.emission)) * double(e.area) * kPi * (twoSided ? 2.0 : 1.0);
            powers.push_back(power);
            totalPower += power;
            emitters_.push_back(e);
        }
    }
    if (totalPower > 0.0) {
        double running = 0.0;
        for (size_t i = 0; i < emitters_.size(); ++i) {
            running += powers[i];
            emitters_[i].pickPdf = float(powers[i] / totalPower);
            cdf_.push_back(float(running / totalPower));
        }
        cdf_.back() = 1.0f;
    } else {
        emitters_.clear(); // emission [0, 0, 0]: nothing to sample
        emitterBase_.assign(scene.meshes.size(), -1);
    }
}

SceneView SceneLights::view() const {
    SceneView v;
    v.shaders = shaders_.data();
    v.emitters = emitters_.data();
    v.emitterCdf = cdf_.data();
    v.emitterCount = uint(emitters_.size());
    return v;
}

} // namespace spw
