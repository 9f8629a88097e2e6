#include "host/scene/lights.h"

#include "host/scene/emitter_kinds.h"

#include "shared/sampling.h"

#include <algorithm>
#include <cmath>

namespace spw {
namespace {

// The radius of a sphere around every vertex of the scene (centred on their bounding box): the
// scale an environment's power is measured at.
double sceneRadius(const Scene& scene) {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const Mesh& m : scene.meshes)
        for (const vec3& p : m.positions) {
            lo = glm::min(lo, glm::dvec3(p));
            hi = glm::max(hi, glm::dvec3(p));
        }
    return lo.x <= hi.x ? 0.5 * glm::length(hi - lo) : 0.0;
}

} // namespace

SceneLights::SceneLights(const Scene& scene) {
    for (const Shader& s : scene.shaders)
        shaders_.push_back(s.params);

    // Every emitter's power in double (radiance up to 1e20 times an area can pass float's
    // range), normalised into pickPdf below.
    std::vector<double> powers;
    emitterBase_.assign(scene.meshes.size(), -1);
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const ShaderParams& sp = shaders_[size_t(mesh.shader)];
        if (maxComponent(sp.emission) <= 0.0f) continue;
        brightest_ = std::max(brightest_, maxComponent(sp.emission));
        emitterBase_[m] = int(emitters_.size());
        bool twoSided = (sp.flags & kShaderTwoSided) != 0;
        for (const uvec3& t : mesh.triangles) {
            Emitter e{};
            e.type = kEmitterTriangle;
            e.p0 = mesh.positions[t.x];
            e.e1 = mesh.positions[t.y] - e.p0;
            e.e2 = mesh.positions[t.z] - e.p0;
            vec3 c = glm::cross(e.e1, e.e2);
            e.area = 0.5f * glm::length(c);
            e.normal = glm::normalize(c);
            e.twoSided = twoSided ? 1u : 0u;
            e.radiance = sp.emission;
            // Power = L * area * pi per emitting side.
            powers.push_back(double(luminance(sp.emission)) * double(e.area) * kPi *
                             (twoSided ? 2.0 : 1.0));
            emitters_.push_back(e);
        }
    }

    const double radius = sceneRadius(scene);
    for (const PunctualLight& p : scene.punctualLights)
        addPunctual(p, radius, powers);

    if (scene.environment) buildEnvironment(*scene.environment, radius, powers);

    double totalPower = 0.0;
    for (double p : powers)
        totalPower += p;
    if (totalPower > 0.0) {
        double running = 0.0;
        for (size_t i = 0; i < emitters_.size(); ++i) {
            running += powers[i];
            emitters_[i].pickPdf = float(powers[i] / totalPower);
            cdf_.push_back(float(running / totalPower));
        }
        cdf_.back() = 1.0f;
    } else {
        emitters_.clear(); // nothing emits: nothing to sample
        emitterBase_.assign(scene.meshes.size(), -1);
    }
    // An environment stays visible to escaping rays even where next-event estimation never
    // picks it (a scene with no geometry has no power to give it).
    for (size_t i = 0; i < emitters_.size(); ++i)
        if (emitters_[i].type == kEmitterEnvironment) environment_ = uint(i);
    if (scene.environment && environment_ == kNoEmitter &&
        maxComponent(scene.environment->radiance) > 0.0f) {
        Emitter e{};
        e.type = kEmitterEnvironment;
        e.radiance = scene.environment->radiance;
        environment_ = uint(emitters_.size());
        emitters_.push_back(e); // pickPdf 0, after the CDF: never picked
    }
}

// A punctual light's emitter and its power, by what its kind takes (emitter_kinds.h):
// - a position: power 4 pi I; for the film's scale, the irradiance at the scene's own size;
// - a direction from infinity: what a disc of the scene's radius facing it intercepts, pi r^2 E
//   (pbrt-v4's estimate for distant lights); for the film's scale, E itself.
void SceneLights::addPunctual(const PunctualLight& p, double radius, std::vector<double>& powers) {
    if (maxComponent(p.intensity) <= 0.0f) return;
    const EmitterKindInfo& kind = *emitterKind(p.kind);
    Emitter e{};
    e.type = p.kind;
    if (kind.flags & kLightTakesPosition) e.p0 = p.position;
    if (kind.flags & kLightTakesDirection) e.normal = p.direction;
    e.radiance = p.intensity;
    const double r = std::max(radius, 1e-30);
    if (p.kind == kEmitterSpot) {
        e.e1 = vec3(p.cosOuter, p.cosInner, 0.0f);
        // 2 pi I (1 - cos) over a cone halfway between the inner and the outer one.
        const double c = 0.5 * (double(p.cosInner) + double(p.cosOuter));
        powers.push_back(2.0 * kPi * (1.0 - c) * double(luminance(p.intensity)));
        brightest_ = std::max(brightest_,
                              float(std::min(double(maxComponent(p.intensity)) / (r * r), 1e30)));
    } else if (kind.flags & kLightTakesPosition) {
        powers.push_back(4.0 * kPi * double(luminance(p.intensity)));
        brightest_ = std::max(brightest_,
                              float(std::min(double(maxComponent(p.intensity)) / (r * r), 1e30)));
    } else {
        powers.push_back(kPi * r * r * double(luminance(p.intensity)));
        brightest_ = std::max(brightest_, maxComponent(p.intensity));
    }
    emitters_.push_back(e);
}

// The environment's emitter, its power, and for a map the texels and CDFs of shared/lights.h.
// Power: what a disc of the scene's radius facing every direction intercepts, pi r^2 times the
// radiance integrated over the sphere (pbrt-v4's estimate for infinite lights).
void SceneLights::buildEnvironment(const Environment& env, double radius,
                                   std::vector<double>& powers) {
    Emitter e{};
    e.type = kEmitterEnvironment;
    e.radiance = env.radiance;
    double integral = 4.0 * kPi * double(luminance(env.radiance)); // over the sphere
    float brightest = maxComponent(env.radiance);
    if (!env.path.empty()) {
        const size_t w = size_t(env.width), h = size_t(env.height);
        envWidth_ = uint(w);
        envHeight_ = uint(h);
        environmentData_.assign(3 * w * h + h + w * h + (h - 1) + (w - 1), 0.0f);
        float* texels = environmentData_.data();
        float* marginal = texels + 3 * w * h;
        float* conditional = marginal + h;
        std::vector<double> rowWeight(h, 0.0);
        integral = 0.0;
        brightest = 0.0f;
        for (size_t y = 0; y < h; ++y) {
            const double sinTheta = std::sin(kPi * (double(y) + 0.5) / double(h));
            double running = 0.0;
            std::vector<double> weights(w);
            for (size_t x = 0; x < w; ++x) {
                vec3 L;
                for (int c = 0; c < 3; ++c)
                    L[c] = env.rgb[(y * w + x) * 3 + size_t(c)] * env.radiance[c];
                for (int c = 0; c < 3; ++c)
                    texels[(y * w + x) * 3 + size_t(c)] = L[c];
                brightest = std::max(brightest, maxComponent(L));
                weights[x] = double(luminance(L)) * sinTheta;
                running += weights[x];
            }
            // A black row is sampled uniformly across (it is never picked: its weight is 0).
            double partial = 0.0;
            for (size_t x = 0; x < w; ++x) {
                partial += running > 0.0 ? weights[x] : 1.0;
                conditional[y * w + x] = float(partial / (running > 0.0 ? running : double(w)));
            }
            conditional[y * w + w - 1] = 1.0f;
            rowWeight[y] = running;
            integral += running;
        }
        double total = integral, partial = 0.0;
        for (size_t y = 0; y < h; ++y) {
            partial += rowWeight[y];
            marginal[y] = total > 0.0 ? float(partial / total) : float(y + 1) / float(h);
        }
        marginal[h - 1] = 1.0f;
        float* rowCos = conditional + w * h;
        for (size_t k = 1; k < h; ++k)
            rowCos[k - 1] = float(std::cos(kPi * double(k) / double(h)));
        float* columnCos = rowCos + (h - 1);
        for (size_t k = 1; k < w; ++k)
            columnCos[k - 1] = float(std::cos(-kPi + 2.0 * kPi * double(k) / double(w)));
        // Each texel spans (2 pi / w) x (pi / h) in (phi, theta): its solid angle is that times
        // sin(theta).
        integral *= 2.0 * kPi * kPi / double(w * h);
    }
    brightest_ = std::max(brightest_, brightest);
    powers.push_back(kPi * radius * radius * integral);
    emitters_.push_back(e);
}

SceneView SceneLights::view() const {
    SceneView v;
    v.shaders = shaders_.data();
    v.emitters = emitters_.data();
    v.emitterCdf = cdf_.data();
    v.emitterCount = uint(cdf_.size());
    v.environmentData = environmentData_.empty() ? nullptr : environmentData_.data();
    return v;
}

} // namespace spw
