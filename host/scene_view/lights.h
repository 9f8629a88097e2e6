// What shading reads of the scene besides the hit: the shader table, and the lights. Every
// triangle of a mesh whose shader emits is an emitter, and so is every punctual light and the
// environment; next-event estimation picks one with probability proportional to its power (the
// CDF), or through the light tree among those with a place (light_tree.h), and the film's
// fixed-point scale reads the brightest emission. Built from the Scene alone, apart from the BVH
// (embree_backend/), as pbrt-v4 builds its lights and light sampler apart from the aggregate.
#pragma once

#include "host/scene/scene.h"
#include "shared/scene_access.h"

#include <limits>
#include <map>
#include <vector>

namespace spw {

class TextureResolver;

class SceneLights {
  public:
    // `textures` reads the images of emission maps (Shader::emissionTexture); a scene with one
    // needs it.
    // A prototype whose emissive triangles times its instances are more than
    // `copiedEmitterLimit` is lit as one emitter per instance (shared/instance_light.h), not as
    // a world-space copy of each triangle per instance.
    explicit SceneLights(const Scene& scene, const TextureResolver* textures = nullptr,
                         size_t copiedEmitterLimit = kMostCopiedEmitters);
    // 4096 copies of a 221-byte emitter (its record, CDF entry and share of the tree) are
    // 0.9 MB: a few lamps placed a few times keep the per-triangle light tree.
    static constexpr size_t kMostCopiedEmitters = 4096;

    // The shading view: shaders, emitters and their CDF.
    SceneView view() const;
    const std::vector<Emitter>& emitters() const { return emitters_; }
    // How many emitters next-event estimation picks from (the CDF's length): every emitter but
    // an environment that has no power to be picked by (no geometry to light).
    uint sampledEmitters() const { return sampled_; }
    // How many emitters, from the first, the light tree holds (0: the scene has no tree).
    uint treeEmitters() const { return treeEmitters_; }
    // The emitters that are instances (kEmitterInstance): the first, and how many follow it.
    uint instanceLights() const { return instanceLights_; }
    uint instanceLightCount() const { return instanceLightCount_; }
    // What the kernels read as the emitter CDF (SceneView::emitterCdf): the CDF, then the
    // light tree (shared/light_tree.h).
    const std::vector<float>& emitterTable() const { return table_; }
    // The environment's emitter index, or kNoEmitter; its map's size (0 x 0: constant).
    uint environment() const { return environment_; }
    uint environmentWidth() const { return envWidth_; }
    uint environmentHeight() const { return envHeight_; }
    const std::vector<float>& lightData() const { return lightData_; }
    float brightestEmission() const { return brightest_; }
    // What the lights hold: the emitters, their CDF and tree, the environment's and emission
    // maps' data (--stats' memory: an emissive instance's triangles are records here).
    size_t bytes() const {
        return emitters_.size() * sizeof(Emitter) + table_.size() * sizeof(float) +
               lightData_.size() * sizeof(float) + shaders_.size() * sizeof(ShaderParams);
    }
    // How many images the emission maps read (each baked once, however many meshes use it).
    size_t emissionImages() const { return emissionImages_.size(); }
    // The emitter index of a mesh's triangle where `instance` places it (kNoInstance: the mesh
    // is in world space), or kNoEmitter; an instance lit as one emitter numbers its triangles
    // (SurfaceHit::emitter, shared/instance_light.h).
    uint emitterOf(uint instance, uint mesh, uint triangle) const {
        const int base = emitterBase_[mesh];
        if (base < 0) return kNoEmitter;
        return uint(base) + triangle + (instance == kNoInstance ? 0u : instanceBase_[instance]);
    }

  private:
    // An emission map's image in the maps' data: where it starts, its size, its mean luminance
    // and its largest channel.
    struct EmissionImage {
        uint offset = 0;
        int width = 1, height = 1;
        double meanLuminance = 0.0;
        float brightest = 0.0f;
    };
    // An emissive mesh of a prototype; where its instances are copied, per corner order (0: the
    // prototype's, 1: a mirroring instance's) and triangle, where there is an image: its record
    // in maps_, and the map's mean over it.
    struct EmissiveMesh {
        const Mesh* mesh;
        const EmissionImage* image;
        std::vector<uint> maps[2];
        std::vector<double> mapped[2];
    };
    // A prototype lit through its instances: its triangles in prototypeTriangles_, their CDF in
    // instanceTable_, their powers (until the CDF is made) and total, their object-space bounds.
    struct PrototypeLight {
        uint first = 0, count = 0, cdf = 0;
        std::vector<double> powers;
        double power = 0.0;
        vec3 lo{std::numeric_limits<float>::max()}, hi{-std::numeric_limits<float>::max()};
    };
    bool emits(const Scene& scene, const Mesh& mesh, const TextureResolver* textures,
               const EmissionImage*& image);
    void addTriangles(const Scene& scene, size_t m, const TextureResolver* textures,
                      std::vector<double>& powers);
    void addInstances(const Scene& scene, const TextureResolver* textures,
                      std::vector<double>& powers);
    void addCopies(const Scene& scene, const std::vector<std::vector<EmissiveMesh>>& byPrototype,
                   std::vector<double>& powers);
    void addPrototypeTriangles(const Scene& scene, const EmissiveMesh& em, PrototypeLight& light);
    void finishPrototypeLight(PrototypeLight& light);
    void addInstanceLights(const Scene& scene, const std::vector<PrototypeLight>& lit,
                           std::vector<double>& powers);
    void placeInstanceLights();
    const EmissionImage& emissionImage(int texture, const TextureResolver& textures);
    // Appends triangle t's record (shared/emission_map.h) to maps_ for Emitter::map; returns
    // the map's mean luminance over the triangle, as the power estimate weighs it.
    double addEmissionMap(const Mesh& mesh, const uvec3& t, const Texture& texture,
                          const EmissionImage& image, Emitter& e);
    void placeEmissionMaps();
    void buildCdf(const std::vector<double>& powers, size_t meshes);
    void buildTree();
    void addPunctual(const PunctualLight& p, double radius, std::vector<double>& powers);
    void buildEnvironment(const Environment& env, double radius, std::vector<double>& powers);
    double buildEnvironmentMap(const Environment& env, float& brightest);

    std::vector<ShaderParams> shaders_;
    std::vector<Emitter> emitters_;
    std::vector<float> table_; // the CDF (sampled_ entries), then the light tree
    uint sampled_ = 0;
    uint treeEmitters_ = 0;
    // Per mesh: the index of its first emitter (a prototype's mesh: from its instance's first),
    // or -1; per instance: the index of its first emitter, where its prototype emits (an
    // instance lit as one emitter: kInstanceTriangle and its first triangle's number).
    std::vector<int> emitterBase_;
    std::vector<uint> instanceBase_;
    size_t copiedEmitterLimit_;
    uint instanceLights_ = 0, instanceLightCount_ = 0;
    // The instanced prototypes' triangles and the instances' CDFs and transforms, until
    // placeInstanceLights puts them behind the emitters and the light tree.
    std::vector<Emitter> prototypeTriangles_;
    std::vector<float> instanceTable_;
    std::vector<uint> mapRecords_; // where in maps_ each emission map's record starts
    float brightest_ = 0.0f;
    uint environment_ = kNoEmitter;
    uint envWidth_ = 0, envHeight_ = 0;
    // The environment map's texels and CDFs, then the emission maps (SceneView::lightData).
    std::vector<float> lightData_;
    // The emission maps' images and records, offsets relative to their start until the
    // constructor moves them behind the environment's data.
    std::vector<float> maps_;
    std::map<int, EmissionImage> emissionImages_; // by Scene::textures index
};

} // namespace spw
