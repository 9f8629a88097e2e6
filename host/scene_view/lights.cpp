#include "host/scene_view/lights.h"

#include "host/scene_view/light_tree.h"

#include "host/scene/emitter_kinds.h"
#include "host/textures/textures.h"

#include "shared/emission_map.h"
#include "shared/instance_light.h"
#include "shared/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace spw {
namespace {

// The most texels an emission map's image keeps (2048 x 2048: 48 MB of floats; the kernels'
// light data is one texel buffer, which Vulkan devices bound at 2^27 elements and up).
constexpr size_t kMaxEmissionTexels = size_t(1) << 22;

// The next coarser MIP level of a w x h image: each texel the mean of up to 2 x 2 (an odd
// side's last texel averaged with itself).
std::vector<vec3> halved(const std::vector<vec3>& in, int& w, int& h) {
    const int hw = (w + 1) / 2, hh = (h + 1) / 2;
    std::vector<vec3> out(size_t(hw) * size_t(hh));
    auto at = [&](int x, int y) {
        return in[size_t(std::min(y, h - 1)) * size_t(w) + size_t(std::min(x, w - 1))];
    };
    for (int y = 0; y < hh; ++y)
        for (int x = 0; x < hw; ++x)
            out[size_t(y) * size_t(hw) + size_t(x)] =
                0.25f * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) +
                         at(2 * x + 1, 2 * y + 1));
    w = hw, h = hh;
    return out;
}

// The radius of a sphere around every vertex of the scene (centred on their bounding box; an
// instance's vertices by its prototype's bounds): the scale an environment's power is measured
// at.
double sceneRadius(const Scene& scene) {
    glm::dvec3 lo, hi;
    sceneBounds(scene, lo, hi);
    return lo.x <= hi.x ? 0.5 * glm::length(hi - lo) : 0.0;
}

} // namespace

SceneLights::SceneLights(const Scene& scene, const TextureResolver* textures,
                         size_t copiedEmitterLimit)
    : copiedEmitterLimit_(copiedEmitterLimit) {
    for (const Shader& s : scene.shaders)
        shaders_.push_back(s.params);

    // Every emitter's power in double (radiance up to 1e20 times an area can pass float's
    // range), normalised into pickPdf below.
    std::vector<double> powers;
    emitterBase_.assign(scene.meshes.size(), -1);
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        addTriangles(scene, m, textures, powers);
    addInstances(scene, textures, powers);

    // The lights with a place first, behind the triangles: the light tree's emitters lead the
    // table (shared/light_tree.h).
    const double radius = sceneRadius(scene);
    for (bool placed : {true, false})
        for (const PunctualLight& p : scene.punctualLights)
            if (((emitterKind(p.kind)->flags & kLightTakesPosition) != 0) == placed)
                addPunctual(p, radius, powers);

    if (scene.environment) buildEnvironment(*scene.environment, radius, powers);
    placeEmissionMaps();
    buildCdf(powers, scene.meshes.size());
    buildTree();

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
    placeInstanceLights();
}

// The emission maps go behind the environment's data, which starts at 0.
void SceneLights::placeEmissionMaps() {
    if (maps_.empty()) return;
    const uint base = uint(lightData_.size());
    for (uint record : mapRecords_) {     // once each, however many instances' emitters share it
        float& image = maps_[record + 6]; // the record's image offset (emission_map.h)
        image = glm::uintBitsToFloat(glm::floatBitsToUint(image) + base);
    }
    for (std::vector<Emitter>* list : {&emitters_, &prototypeTriangles_})
        for (Emitter& e : *list)
            if (e.map != kNoEmissionMap) e.map += base;
    lightData_.insert(lightData_.end(), maps_.begin(), maps_.end());
    maps_.clear();
}

// The light tree over the leading emitters with a place, where it picks differently from the
// CDF (two or more emitters, not all with the same bounds).
void SceneLights::buildTree() {
    uint count = 0;
    while (count < sampled_ && inLightTree(emitters_[count]))
        ++count;
    if (!lightTreeChangesPicks(emitters_, count)) return;
    treeEmitters_ = count;
    appendLightTree(emitters_, count, table_);
}

// Every emitter's pickPdf and the CDF, from their powers; without any power, no emitter.
void SceneLights::buildCdf(const std::vector<double>& powers, size_t meshes) {
    double totalPower = 0.0;
    for (double p : powers)
        totalPower += p;
    if (totalPower > 0.0) {
        double running = 0.0;
        for (size_t i = 0; i < emitters_.size(); ++i) {
            running += powers[i];
            emitters_[i].pickPdf = float(powers[i] / totalPower);
            table_.push_back(float(running / totalPower));
        }
        table_.back() = 1.0f;
        sampled_ = uint(table_.size());
    } else {
        emitters_.clear(); // nothing emits: nothing to sample
        emitterBase_.assign(meshes, -1);
        instanceBase_.clear();
        instanceLightCount_ = 0;
    }
}

// Whether mesh m's shader emits, with its emission map's image in `image` (null: none); notes
// its brightest emission for the film.
bool SceneLights::emits(const Scene& scene, const Mesh& mesh, const TextureResolver* textures,
                        const EmissionImage*& image) {
    const Shader& shader = scene.shaders[size_t(mesh.shader)];
    const ShaderParams& sp = shader.params;
    image = nullptr;
    if (maxComponent(sp.emission) <= 0.0f) return false;
    if (shader.emissionTexture >= 0) {
        if (!textures || !textures->active())
            throw std::logic_error("an emission map's image needs the scene's texture resolver");
        image = &emissionImage(shader.emissionTexture, *textures);
    }
    brightest_ =
        std::max(brightest_, maxComponent(sp.emission) * (image ? image->brightest : 1.0f));
    return true;
}

namespace {

// The emitter of the world-space triangle (p0, p1, p2) of an emissive shader.
Emitter triangleEmitter(const ShaderParams& sp, const vec3& p0, const vec3& p1, const vec3& p2) {
    Emitter e{};
    e.type = kEmitterTriangle;
    e.p0 = p0;
    e.e1 = p1 - p0;
    e.e2 = p2 - p0;
    const vec3 c = glm::cross(e.e1, e.e2);
    e.area = 0.5f * glm::length(c);
    e.normal = glm::normalize(c);
    e.twoSided = (sp.flags & kShaderTwoSided) != 0 ? 1u : 0u;
    e.radiance = sp.emission;
    return e;
}

// A triangle's corners as a mirroring instance takes them: the second and third swapped.
uvec3 cornersOf(const uvec3& t, bool mirrors) {
    return mirrors ? uvec3(t.x, t.z, t.y) : t;
}

// Power = L * area * pi per emitting side, L the emission times its map's mean over the triangle.
double trianglePower(const ShaderParams& sp, double area, bool twoSided, double mapped) {
    return double(luminance(sp.emission)) * mapped * area * kPi * (twoSided ? 2.0 : 1.0);
}

double trianglePower(const ShaderParams& sp, const Emitter& e, double mapped) {
    return trianglePower(sp, double(e.area), e.twoSided != 0u, mapped);
}

} // namespace

// Every triangle of world-space mesh m, if its shader emits: an emitter each, with its power.
void SceneLights::addTriangles(const Scene& scene, size_t m, const TextureResolver* textures,
                               std::vector<double>& powers) {
    const Mesh& mesh = scene.meshes[m];
    const EmissionImage* image = nullptr;
    if (mesh.prototype >= 0 || !emits(scene, mesh, textures, image)) return;
    const Shader& shader = scene.shaders[size_t(mesh.shader)];
    emitterBase_[m] = int(emitters_.size());
    for (const uvec3& t : mesh.triangles) {
        Emitter e = triangleEmitter(shader.params, mesh.positions[t.x], mesh.positions[t.y],
                                    mesh.positions[t.z]);
        double mapped = 1.0;
        if (image)
            mapped =
                addEmissionMap(mesh, t, scene.textures[size_t(shader.emissionTexture)], *image, e);
        powers.push_back(trianglePower(shader.params, e, mapped));
        emitters_.push_back(e);
    }
}

// Every emissive triangle of a prototype, at each instance placing it. A prototype placed few
// enough times (kMostCopiedEmitters) has a world-space emitter per triangle per instance, as
// Cycles 3.x lists an instanced mesh's triangles once per object (addCopies); one placed more
// often is one emitter per instance, whose triangles are the prototype's, held once
// (addInstanceLights, shared/instance_light.h). Either way a triangle's offset in its prototype's
// emissive triangles (emitterBase_) names it within an instance.
void SceneLights::addInstances(const Scene& scene, const TextureResolver* textures,
                               std::vector<double>& powers) {
    std::vector<size_t> placements(scene.prototypes.size(), 0);
    std::vector<int> orders(scene.prototypes.size(), 0); // bit k: an instance of order k
    for (const Instance& inst : scene.instances) {
        ++placements[inst.prototype];
        orders[inst.prototype] |= inst.mirrors ? 2 : 1;
    }
    std::vector<std::vector<EmissiveMesh>> copied(scene.prototypes.size());
    std::vector<PrototypeLight> lit(scene.prototypes.size());
    for (size_t p = 0; p < scene.prototypes.size(); ++p) {
        const bool copies =
            emissiveTriangles(scene, scene.prototypes[p]) * placements[p] <= copiedEmitterLimit_;
        int offset = 0;
        for (uint m : scene.prototypes[p].meshes) {
            EmissiveMesh em{&scene.meshes[m], nullptr, {}, {}};
            if (!emits(scene, *em.mesh, textures, em.image)) continue;
            emitterBase_[m] = offset;
            offset += int(em.mesh->triangles.size());
            if (!copies) {
                addPrototypeTriangles(scene, em, lit[p]);
                continue;
            }
            const int map = scene.shaders[size_t(em.mesh->shader)].emissionTexture;
            const Texture* texture = em.image ? &scene.textures[size_t(map)] : nullptr;
            for (int order = 0; texture && order < 2; ++order)
                if (orders[p] & (1 << order))
                    for (const uvec3& t : em.mesh->triangles) {
                        Emitter e{};
                        em.mapped[order].push_back(addEmissionMap(
                            *em.mesh, cornersOf(t, order == 1), *texture, *em.image, e));
                        em.maps[order].push_back(e.map);
                    }
            copied[p].push_back(std::move(em));
        }
        finishPrototypeLight(lit[p]);
        if (!copies && lit[p].count == 0) // no power: no triangle to hit either
            for (uint m : scene.prototypes[p].meshes)
                emitterBase_[m] = -1;
    }
    instanceBase_.assign(scene.instances.size(), 0u);
    addCopies(scene, copied, powers);
    addInstanceLights(scene, lit, powers);
}

// The world-space emitters of the copied prototypes' instances (reserved at once: a forest's
// lights are most of its bytes).
void SceneLights::addCopies(const Scene& scene,
                            const std::vector<std::vector<EmissiveMesh>>& byPrototype,
                            std::vector<double>& powers) {
    size_t count = emitters_.size();
    for (const Instance& inst : scene.instances)
        for (const EmissiveMesh& em : byPrototype[inst.prototype])
            count += em.mesh->triangles.size();
    if (count == emitters_.size()) return;
    emitters_.reserve(count + scene.instances.size() + scene.punctualLights.size() + 1);
    powers.reserve(count + scene.instances.size() + scene.punctualLights.size() + 1);
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (byPrototype[inst.prototype].empty()) continue;
        instanceBase_[i] = uint(emitters_.size());
        const int order = inst.mirrors ? 1 : 0;
        for (const EmissiveMesh& em : byPrototype[inst.prototype]) {
            const ShaderParams& sp = scene.shaders[size_t(em.mesh->shader)].params;
            auto world = [&](uint v) {
                return vec3(inst.toWorld * vec4(em.mesh->positions[v], 1.0f));
            };
            for (size_t k = 0; k < em.mesh->triangles.size(); ++k) {
                // A mirroring instance takes its triangles' corners as a copy of it does (the
                // loaders turn a mirrored copy's winding, keeping its front faces the file's),
                // so its emitters are the copy's, corner for corner.
                const uvec3 t = cornersOf(em.mesh->triangles[k], inst.mirrors);
                Emitter e = triangleEmitter(sp, world(t.x), world(t.y), world(t.z));
                if (em.image) e.map = em.maps[order][k];
                powers.push_back(trianglePower(sp, e, em.image ? em.mapped[order][k] : 1.0));
                emitters_.push_back(e);
            }
        }
    }
}

// Mesh em's triangles in its prototype's object space, appended to the prototype's light with
// their powers (in double: radiance up to 1e20 times an area can pass float's range), which
// finishPrototypeLight makes their shares.
void SceneLights::addPrototypeTriangles(const Scene& scene, const EmissiveMesh& em,
                                        PrototypeLight& light) {
    const Shader& shader = scene.shaders[size_t(em.mesh->shader)];
    if (light.count == 0) light.first = uint(prototypeTriangles_.size());
    for (const uvec3& t : em.mesh->triangles) {
        const vec3 &p0 = em.mesh->positions[t.x], &p1 = em.mesh->positions[t.y],
                   &p2 = em.mesh->positions[t.z];
        Emitter e = triangleEmitter(shader.params, p0, p1, p2);
        if (!(e.area > 0.0f)) e.normal = vec3(0.0f, 0.0f, 1.0f); // never picked: no power
        double mapped = 1.0;
        if (em.image)
            mapped = addEmissionMap(*em.mesh, t, scene.textures[size_t(shader.emissionTexture)],
                                    *em.image, e);
        // The area in double: a prototype modelled large and placed small can pass float's.
        const double area = 0.5 * glm::length(glm::cross(glm::dvec3(e.e1), glm::dvec3(e.e2)));
        light.powers.push_back(trianglePower(shader.params, area, e.twoSided != 0u, mapped));
        light.power += light.powers.back();
        for (const vec3& p : {p0, p1, p2}) {
            light.lo = glm::min(light.lo, p);
            light.hi = glm::max(light.hi, p);
        }
        prototypeTriangles_.push_back(e);
        ++light.count;
    }
}

// The prototype's triangles' shares of its power, and their CDF in instanceTable_.
void SceneLights::finishPrototypeLight(PrototypeLight& light) {
    if (light.count == 0 || !(light.power > 0.0)) {
        light.count = 0;
        return;
    }
    light.cdf = uint(instanceTable_.size());
    double running = 0.0;
    for (uint k = 0; k < light.count; ++k) {
        running += light.powers[k];
        prototypeTriangles_[light.first + k].pickPdf = float(light.powers[k] / light.power);
        instanceTable_.push_back(float(running / light.power));
    }
    instanceTable_.back() = 1.0f;
    light.powers = {};
}

// One emitter per instance of a prototype not copied (shared/instance_light.h's words; the
// offsets relative to prototypeTriangles_ and instanceTable_ until placeInstanceLights), with
// its power: the prototype's, times the transform's scale of area (|det|^(2/3), exact for a
// similarity; otherwise an estimate, which only makes the pick less apt).
void SceneLights::addInstanceLights(const Scene& scene, const std::vector<PrototypeLight>& lit,
                                    std::vector<double>& powers) {
    instanceLights_ = uint(emitters_.size());
    uint numbered = 0; // the instances' triangles so far: the next one's hit index
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const PrototypeLight& light = lit[inst.prototype];
        if (light.count == 0) continue;
        if (numbered > kInstanceTriangle - 1u - light.count)
            throw std::runtime_error("the emissive triangles of instances are more than 2^31");
        instanceBase_[i] = kInstanceTriangle | numbered;
        Emitter e{};
        e.type = kEmitterInstance;
        e.p0 = vec3(std::numeric_limits<float>::max());
        e.e1 = -e.p0;
        for (int c = 0; c < 8; ++c) {
            const vec3 corner(c & 1 ? light.hi.x : light.lo.x, c & 2 ? light.hi.y : light.lo.y,
                              c & 4 ? light.hi.z : light.lo.z);
            const vec3 w = vec3(inst.toWorld * vec4(corner, 1.0f));
            e.p0 = glm::min(e.p0, w);
            e.e1 = glm::max(e.e1, w);
        }
        e.area = glm::uintBitsToFloat(uint(instanceTable_.size()));
        for (int col = 0; col < 4; ++col)
            for (int r = 0; r < 3; ++r)
                instanceTable_.push_back(inst.toWorld[col][r]);
        e.e2 = glm::uintBitsToFloat(uvec3(light.first, light.count, light.cdf));
        e.twoSided = numbered;
        e.normal = vec3(inst.mirrors ? -1.0f : 1.0f, 0.0f, 0.0f);
        const double det = std::fabs(glm::determinant(glm::dmat3(mat3(inst.toWorld))));
        powers.push_back(light.power * std::cbrt(det * det));
        emitters_.push_back(e);
        numbered += light.count;
        ++instanceLightCount_;
    }
}

// The prototypes' triangles go behind every other emitter, their CDFs and the instances'
// transforms behind the light tree: the instances' offsets become the tables' own.
void SceneLights::placeInstanceLights() {
    if (instanceLightCount_ == 0) return;
    const uint first = uint(emitters_.size()), words = uint(table_.size());
    auto moved = [](float& word, uint by) {
        word = glm::uintBitsToFloat(glm::floatBitsToUint(word) + by);
    };
    for (uint i = instanceLights_; i < instanceLights_ + instanceLightCount_; ++i) {
        Emitter& e = emitters_[i];
        moved(e.area, words);
        moved(e.e2.x, first);
        moved(e.e2.z, words);
    }
    emitters_.insert(emitters_.end(), prototypeTriangles_.begin(), prototypeTriangles_.end());
    table_.insert(table_.end(), instanceTable_.begin(), instanceTable_.end());
    prototypeTriangles_.clear();
    instanceTable_.clear();
}

// An emission map's image, read once into maps_ (linear RGB, row by row); one larger than
// kMaxEmissionTexels is averaged down to a coarser level until it fits.
const SceneLights::EmissionImage& SceneLights::emissionImage(int texture,
                                                             const TextureResolver& textures) {
    if (const auto found = emissionImages_.find(texture); found != emissionImages_.end())
        return found->second;
    EmissionImage image;
    std::vector<vec3> texels = textures.finestLevel(texture, image.width, image.height);
    while (size_t(image.width) * size_t(image.height) > kMaxEmissionTexels)
        texels = halved(texels, image.width, image.height);
    image.offset = uint(maps_.size());
    double sum = 0.0;
    for (const vec3& t : texels) {
        maps_.insert(maps_.end(), {t.x, t.y, t.z});
        sum += double(luminance(t));
        image.brightest = std::max(image.brightest, maxComponent(t));
    }
    image.meanLuminance = sum / double(texels.size());
    return emissionImages_[texture] = image;
}

double SceneLights::addEmissionMap(const Mesh& mesh, const uvec3& t, const Texture& texture,
                                   const EmissionImage& image, Emitter& e) {
    // Image coordinates (s, t) = (u, 1 - v) of the vertices, after the texture transform.
    vec2 st[3];
    for (int k = 0; k < 3; ++k) {
        vec2 uv = mesh.uvs.empty() ? vec2(0.0f) : mesh.uvs[t[k]];
        if (texture.uvTransformed) uv = vec2(texture.uvTransform * vec3(uv, 1.0f));
        st[k] = vec2(uv.x, 1.0f - uv.y);
    }
    const vec2 d1 = st[1] - st[0], d2 = st[2] - st[0];
    e.map = uint(maps_.size());
    mapRecords_.push_back(e.map);
    auto sized = [](int texels, Texture::Wrap wrap) { // a side and its wrap mode, in one word
        return glm::uintBitsToFloat(uint(texels) | wrapMode(wrap) << 30u);
    };
    maps_.insert(maps_.end(),
                 {st[0].x, st[0].y, d1.x, d1.y, d2.x, d2.y, glm::uintBitsToFloat(image.offset),
                  sized(image.width, texture.wrapU), sized(image.height, texture.wrapV)});
    // The map's mean over the triangle, from an n x n grid of stratified points, n growing with
    // the texels the triangle covers (at most 32). Where the grid misses the triangle's bright
    // texels, the pick probability is only less apt: the floor, 1 % of the image's mean, keeps
    // every triangle of a lit image pickable.
    const float texels =
        0.5f * std::fabs(d1.x * d2.y - d1.y * d2.x) * float(image.width) * float(image.height);
    const float side = std::sqrt(texels); // huge, infinite or NaN for far-flung coordinates
    const int n = side < 32.0f ? std::max(4, int(std::ceil(side))) : 32;
    SceneView view;
    view.lightData = maps_.data();
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const vec2 u((float(i) + 0.5f) / float(n), (float(j) + 0.5f) / float(n));
            sum += double(luminance(emissionMapValue(view, e.map, sampleTriangle(u))));
        }
    return std::max(sum / double(n * n), 0.01 * image.meanLuminance);
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
    if (!env.path.empty()) integral = buildEnvironmentMap(env, brightest);
    brightest_ = std::max(brightest_, brightest);
    powers.push_back(kPi * radius * radius * integral);
    emitters_.push_back(e);
}

// The map's texels and sampling tables, from 0 in lightData_ (shared/environment_light.h);
// returns its luminance integrated over the sphere, and its brightest channel in `brightest`.
double SceneLights::buildEnvironmentMap(const Environment& env, float& brightest) {
    const size_t w = size_t(env.width), h = size_t(env.height);
    envWidth_ = uint(w);
    envHeight_ = uint(h);
    lightData_.assign(3 * w * h + h + w * h + (h - 1) + (w - 1), 0.0f);
    float* texels = lightData_.data();
    float* marginal = texels + 3 * w * h;
    float* conditional = marginal + h;
    std::vector<double> rowWeight(h, 0.0);
    double integral = 0.0;
    brightest = 0.0f;
    std::vector<double> weights(w);
    for (size_t y = 0; y < h; ++y) {
        const double sinTheta = std::sin(kPi * (double(y) + 0.5) / double(h));
        double running = 0.0;
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
    double partial = 0.0;
    for (size_t y = 0; y < h; ++y) {
        partial += rowWeight[y];
        marginal[y] = integral > 0.0 ? float(partial / integral) : float(y + 1) / float(h);
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
    return integral * 2.0 * kPi * kPi / double(w * h);
}

SceneView SceneLights::view() const {
    SceneView v;
    v.shaders = shaders_.data();
    v.emitters = emitters_.data();
    v.emitterCdf = table_.data();
    v.emitterCount = sampled_;
    v.lightData = lightData_.empty() ? nullptr : lightData_.data();
    return v;
}

} // namespace spw
