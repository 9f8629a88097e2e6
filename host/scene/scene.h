// The scene: everything docs/scene-format.md describes, resolved to world space and immutable once
// loaded. Backends read it; nothing writes it after loadScene() returns.
#pragma once

#include "host/image/filter.h"
#include "shared/texture_wrap.h"
#include "shared/types.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace spw {

// A scene error: where in which file, and what is wrong. The CLI prints "file:line: message"
// and exits 2.
// A problem with the file as a whole (it cannot be opened, it is a folder) has no line: line 0,
// printed "file: message".
class SceneError : public std::runtime_error {
  public:
    SceneError(std::string file, int line, const std::string& message)
        : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " +
                             message),
          file_(std::move(file)), line_(line) {}
    const std::string& file() const { return file_; }
    int line() const { return line_; }

  private:
    std::string file_;
    int line_;
};

// The ranges of the scene format that keep every ray Embree sees valid and every product of the
// shading math finite in float (docs/scene-format.md).
// Every position, after its transforms, lies within this many units of the camera: squared
// distances stay below 1e31, far inside float, and ray origins far inside Embree's 1.8e18.
constexpr double kMaxDistance = 1e15;
// Emission (each channel) and a quad light's intensity x colour: products with BSDF values,
// MIS weights and 1/pdf keep about 1e18 of headroom below float's 3.4e38.
constexpr double kMaxRadiance = 1e20;
// Bounces a path may take (settings: max depth): what the compact ray record's bounce field holds,
// so that every backend renders every scene the loader accepts.
constexpr int kMaxDepth = 0x7FFF;
// Layered textures: levels from the root to a leaf, and textures in all (aliases shared).
constexpr int kMaxTextureDepth = 64;
constexpr int kMaxTextures = 1 << 16;
// The sorted pipeline's hit key packs (shader, object, texture order) into 12 + 20 + 32 bits, the
// all-ones key meaning a miss: at most 4095 shaders (one per light included) and 2^20 objects
// (one per light included).
constexpr int kMaxShaders = (1 << 12) - 1;
constexpr int kMaxObjects = 1 << 20;
// Instances (Scene::instances): Embree's geometry ids are 32 bits, and at the 1.8 KB of peak
// memory a glTF placement costs (docs/performance.md, "Production scale") 2^26 instances are
// over 100 GB, past any machine this renders on.
constexpr int kMaxInstances = 1 << 26;
// An emissive prototype's triangles counted once for each instance placing it: a hit on one
// names it by that count in 31 bits (shared/instance_light.h's kInstanceTriangle).
constexpr size_t kMaxInstancedEmitters = (size_t(1) << 31) - 1;
// A glTF accessor holds at most this many values (elements x components): 2 GiB as the doubles
// the loader reads them into, and 2^28 / 3 vertices a primitive, far past what one mesh needs.
constexpr size_t kMaxGltfAccessorValues = size_t(1) << 28;
// An image texture, read tile by tile through the cache, has at most this many pixels (32768^2)
// and sides of at most 65536; images read whole (emission textures, environment maps) are
// limited to image_io.h's kMaxImagePixels (2^26, 8192^2). Checked from the file's header,
// before any pixel is read: a 400-byte PNG can claim 100000 x 100000.
constexpr long long kMaxTexturePixels = 1LL << 30;
constexpr long long kMaxTextureSide = 1LL << 16;

struct ImageSettings {
    int width = 512;
    int height = 512;
    int sampleBase = 1; // n: n*n samples per pixel per iteration
    int iterations = 1;
    // False for a file whose format carries no sampling setting (a glTF file rendered as the
    // scene): `spillway render` then picks a default a user would accept (render_command.cpp).
    bool samplingStated = true;
    int samplesPerIteration() const { return sampleBase * sampleBase; }
};

struct Settings {
    int minDepth = 3;
    int maxDepth = 16;
    float threshold = 0.1f;
    int bucketSize = 32;
    int shadingSize = 4096;
    int binExponent = 15;
    double memoryBudgetMiB = 512.0;
    // The texture system's tile cache. 1 GiB, OpenImageIO's own default: on a machine of 24 GiB
    // it leaves the rest to geometry and rays, and holds every scene but the out-of-core ones.
    double textureCacheMiB = 1024.0;
    std::uint32_t seed = 0;
    // Adaptive sampling (host/image/film.h): off at 0; 8 x 8 tiles whose relative RMS error
    // estimate is below it stop taking samples, once they have adaptiveMinSamples.
    double adaptiveThreshold = 0.0;
    int adaptiveMinSamples = 16;
};

enum class CameraType { PinHole, ThinLens };

struct Camera {
    CameraType type = CameraType::PinHole;
    // Looks along local -Z, +Y up. Its translation is always zero: the world is camera-relative
    // (Scene::origin is where the camera stands in the scene file's coordinates).
    mat4 cameraToWorld{1.0f};
    float focalLength = 35.0f;       // mm
    float filmWidth = 35.0f;         // mm
    std::optional<float> fovDegrees; // horizontal; overrides the focal length
    float apertureRadius = 0.0f;
    float focalDistance = 1.0f;
    // tan(horizontal half angle)
    float tanHalfFovX() const;
};

// Independent, Grid and Stratified place the camera sample in the pixel and draw every other
// dimension independently; Sobol draws every dimension, the pixel's included, from Owen-scrambled
// Sobol points (shared/rng.h).
enum class SamplerType { Independent, Grid, Stratified, Sobol };
const char* samplerName(SamplerType s);
// The sampler named `name`, or nothing.
std::optional<SamplerType> parseSampler(const std::string& name);

enum class TextureType { Constant, Standard, Layered };
// Where the encoded bytes of an image embedded in a scene file lie: `length` bytes at `offset`
// of `file` (a glTF buffer in the file or beside it), read a piece at a time and never held
// whole; where `base64` is set, written out as base64 text from `offset` on (a data: URI in the
// file's JSON: 4 characters for every 3 bytes, decoded as they are read); or, where `bytes` is
// set (an image Spillway made, or a data: URI not found as it is in the file), in memory.
struct EmbeddedImage {
    std::string file;
    std::uint64_t offset = 0, length = 0;
    std::shared_ptr<const std::string> bytes;
    bool base64 = false;
    // The bytes `file` holds from `offset`: `length`, or its base64 text's characters.
    std::uint64_t stored() const { return base64 ? (length + 2) / 3 * 4 : length; }
};
struct Texture {
    TextureType type = TextureType::Constant;
    vec3 colour{1.0f};
    std::string path; // Standard: absolute path of the image
    // Standard, an image embedded in the scene file (a glTF buffer or data: URI), read under
    // `path`, a name no file has ("model.glb#image0.png"); null for an image file.
    std::shared_ptr<const EmbeddedImage> embedded;
    // Standard: an affine map of the texture coordinates before the lookup (glTF's
    // KHR_texture_transform), and how much it stretches a footprint (its larger scale).
    bool uvTransformed = false;
    mat3 uvTransform{1.0f};
    float footprintScale = 1.0f;
    // Standard: what a lookup outside [0, 1] reads along u and along v (glTF's sampler wrapS,
    // wrapT): the image repeated, its edge texels (clamped) or the image mirrored; the values
    // are shared/texture_wrap.h's modes (wrapMode).
    enum class Wrap : std::uint8_t {
        Repeat = kWrapRepeat,
        Clamp = kWrapClamp,
        Mirror = kWrapMirror
    };
    Wrap wrapU = Wrap::Repeat, wrapV = Wrap::Repeat;
    bool wraps() const { return wrapU != Wrap::Repeat || wrapV != Wrap::Repeat; }
    // Standard: the image's channels read, from `channel` on (3: alpha alone); where the image
    // has no such channel, the value is 1 (glTF: an image without alpha is opaque).
    int channel = 0;
    // Standard: the values as stored, never sRGB-decoded (glTF's alpha, normal and
    // metallic-roughness images); otherwise 8-bit images are taken to be sRGB.
    bool linear = false;
    int upper = -1, lower = -1, mask = -1; // Layered: indices into Scene::textures
    int line = 0;                          // where the scene file defines it
};

// A wrap mode as the shared wrapCoordinate() takes it.
inline uint wrapMode(Texture::Wrap wrap) {
    return uint(wrap);
}

// An alpha cut-out (glTF's alphaMode MASK): the surface is there only where its alpha, `alpha`
// times the first channel of the texture tree `texture` (or alone, -1), is at least `cutoff`.
// Elsewhere rays pass through it, camera, bounce and shadow rays alike (the BVH's hit filter,
// embree_backend/cutouts.h). Stochastic (glTF's alphaMode BLEND): each ray that meets it sees it
// with probability alpha, and passes through it otherwise.
struct Cutout {
    bool enabled = false;
    bool stochastic = false;
    float alpha = 1.0f;
    int texture = -1;
    float cutoff = 0.5f;
};

struct Shader {
    ShaderParams params{};
    int texture = -1; // root of the texture tree, or -1
    Cutout cutout;
    // A tangent-space normal map (glTF's normalTexture), or -1: its texel t tilts the shading
    // normal to (2 t - 1) (x and y times normalScale) in the frame of the triangle's texture
    // coordinates (HitSetup::tiltedNormal).
    int normalTexture = -1;
    float normalScale = 1.0f;
    // CoatedMetallicRoughness with kShaderCoatNormal: the coat's own normal map
    // (KHR_materials_clearcoat's clearcoatNormalTexture), tilting the interpolated normal as
    // normalTexture does, or -1: the coat takes the interpolated normal (the base's normal map
    // is the base's alone). Carried in SurfaceHit::extension (HitSetup::applyMaps).
    int coatNormalTexture = -1;
    float coatNormalScale = 1.0f;
    // MetallicRoughness: glTF's metallicRoughnessTexture, or -1: its texel's blue channel times
    // params.metallic is the hit's metallic, its green times `roughness` (the factor alpha was
    // made from) the hit's roughness, carried in SurfaceHit::material (kShaderHitParams).
    int metallicRoughnessTexture = -1;
    float roughness = 1.0f;
    // An emission map (glTF's emissiveTexture), or -1: a Standard texture whose image times
    // params.emission is the radiance at each point of the mesh's triangles. The kernels read it
    // from the light data (shared/emission_map.h), not hit setup: light sampling needs it too.
    int emissionTexture = -1;

    // The model's extension parameters, with kShaderHitExtension (shared/bsdf.h's shaderAtHit
    // says what each of the four slots is to each model): slot k at a hit is its factor times
    // component `component` of texture `texture`'s texel there, or the factor alone at -1; carried
    // as halves in SurfaceHit::extension.
    struct ExtensionMap {
        int texture = -1;
        int component = 0;
        float factor = 0.0f;
    };
    std::array<ExtensionMap, 4> extension{};

    // Maps beyond the colour, looked up in hit setup after it (HitSetup::applyMaps).
    bool hasMaps() const {
        return normalTexture >= 0 || metallicRoughnessTexture >= 0 ||
               (params.flags & kShaderHitExtension) != 0u;
    }
    // Whether hit setup looks anything up at a hit's texture coordinates.
    bool looksUpTextures() const { return texture >= 0 || hasMaps(); }
    std::string typeName;
    int line = 0;
};

// A triangle mesh in world space. Vertex attributes are per vertex; normals and uvs are empty
// when the OBJ has none.
struct Mesh {
    std::vector<vec3> positions;
    std::vector<vec3> normals;
    std::vector<vec2> uvs;
    // Per vertex, a factor of the albedo (glTF's COLOR_0, HitSetup::applyVertexColour); empty
    // when the mesh has none.
    std::vector<vec3> colours;
    std::vector<uvec3> triangles;
    int shader = 0;
    std::string name;         // the file, or "quad light N"
    int droppedTriangles = 0; // zero-area triangles left out when loading
    // The prototype (Scene::prototypes) this mesh belongs to, its vertices then in the
    // prototype's own frame, placed only by instances; -1: in world space, placed once.
    int prototype = -1;

    // Texture coordinates interpolated at Embree's barycentrics (u, v) of triangle `prim`;
    // (0, 0) where the mesh has none.
    vec2 uvAt(uint prim, float u, float v) const {
        if (uvs.empty()) return vec2(0.0f);
        const uvec3 tri = triangles[prim];
        return (1.0f - u - v) * uvs[tri.x] + u * uvs[tri.y] + v * uvs[tri.z];
    }
};

// Meshes placed many times without copies (glTF's nodes naming one mesh, a YAML object's
// `instances:`): one Embree scene of their own, placed in the world by instances. An emissive
// prototype's triangles are lights at each placement (SceneLights makes a world-space emitter per
// triangle per instance; the geometry stays one).
struct Prototype {
    std::vector<uint> meshes; // indices into Scene::meshes, each with Mesh::prototype this one
    vec3 lo{0.0f}, hi{0.0f};  // the meshes' bounds, in the prototype's frame
    std::string name;         // the file and mesh, for messages and --stats
};

// Where an index into Scene::instances is expected: none (a mesh placed in world space itself).
constexpr uint kNoInstance = 0xFFFFFFFFu;

// One placement of a prototype: its frame to the camera-relative world (an affine map, made in
// double and rounded once) and what hit setup needs of it: the inverse transpose that takes
// normals, and whether the map mirrors (turning its triangles' winding, as a copy's would be).
struct Instance {
    uint prototype = 0;
    mat4 toWorld{1.0f};
    mat3 normalToWorld{1.0f};
    bool mirrors = false;
};

// The instance placing prototype `prototype` by `toWorld` (a finite affine map in double,
// camera-relative); empty `error` unless it cannot be one: singular, or reaching beyond
// kMaxDistance with the prototype's bounds.
Instance makeInstance(const Prototype& proto, uint prototype, const glm::dmat4& toWorld,
                      std::string& error);

// Room for one more vertex behind `mesh`'s positions (a reallocation only where there is none),
// so that Embree can read the last vertex with one 16-byte load from the mesh's own array, which
// it then shares instead of copying (embree_backend/embree_scene.cpp).
inline void padForSharing(Mesh& mesh) {
    if (mesh.positions.capacity() == mesh.positions.size())
        mesh.positions.reserve(mesh.positions.size() + 1);
}

// A punctual light of an emitter kind that takes a position or a direction
// (host/scene/emitter_kinds.h): a point light's `intensity` W/sr in every direction at
// `position`; a directional light's irradiance `intensity` W/m^2 arriving along the unit
// `direction` (intensity x colour, both).
struct PunctualLight {
    uint kind = 0; // kEmitter*
    vec3 position{0.0f};
    vec3 direction{0.0f, -1.0f, 0.0f};
    vec3 intensity{1.0f};
    // A spot light's cone (shared/spot_light.h): full intensity within the inner angle, none
    // beyond the outer one. glTF's defaults: 0 and pi/4.
    float cosInner = 1.0f, cosOuter = 0.70710678f;
    int line = 0;
};

// Radiance at infinity: a constant, or a lat-long map (shared/lights.h draws its layout) scaled
// by `radiance`.
struct Environment {
    vec3 radiance{1.0f};
    std::string path; // the map's absolute path, or empty for a constant environment
    int width = 0, height = 0;
    std::vector<float> rgb; // the map, linear RGB, row 0 straight up
    int line = 0;
};

// Rendering is camera-relative: the loader applies every transform in double and subtracts the
// camera's position before rounding to float, so the float world has the camera at (0, 0, 0)
// and the image does not depend on where the scene sits in the file's coordinates.
struct Scene {
    std::string file;
    glm::dvec3 origin{0.0}; // the camera's position in the scene file's coordinates
    ImageSettings image;
    Settings settings;
    Camera camera;
    Filter filter;
    SamplerType sampler = SamplerType::Sobol; // measured best: docs/performance.md, "Samplers"
    std::vector<Shader> shaders; // scene shaders first, then one emissive Null per quad light
    std::vector<Texture> textures;
    std::vector<Mesh> meshes; // objects first, then the quad lights' geometry
    int objectCount = 0;
    int quadLightCount = 0;
    std::vector<Prototype> prototypes;
    std::vector<Instance> instances;
    std::vector<PunctualLight> punctualLights;
    std::optional<Environment> environment;
    // What the file holds that is not rendered ("file: what"), once each: the CLI prints them.
    std::vector<std::string> warnings;
    // Every file the loaders read besides `file` whose bytes the image depends on and that the
    // model does not hold whole: OBJ files, glTF files and their external buffers. A checkpoint's
    // identity hashes them (host/render/checkpoint.cpp), so a placed file changed between a
    // checkpoint and --resume (or between partials) is found.
    std::vector<std::string> inputs;

    bool usesTextures() const;
    // The triangles the scene renders, every instance's counted.
    double renderedTriangles() const;
};

// The triangles of `proto`'s meshes whose shaders emit: the emitters each instance of it adds.
size_t emissiveTriangles(const Scene& scene, const Prototype& proto);
// The bounds of every vertex the scene renders, in double: world-space meshes' vertices, and
// each instance's prototype bounds moved to world space; lo > hi where the scene has none.
void sceneBounds(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi);

// Empty when `p` (relative to the camera) lies within kMaxDistance of it; else the message that
// says so, naming `what` (the loader and the OBJ reader report it at their own file and line).
std::string beyondReach(const glm::dvec3& p, const std::string& what);

// A number as the scene format writes it in ranges and messages: 0.25, 1e20, 1e-5, inf.
std::string formatNumber(double v);

} // namespace spw
