// The glTF reader that gltf_loader.cpp (the document, its node graph, cameras and lights),
// gltf_meshes.cpp (accessors and meshes) and gltf_materials.cpp (materials and their images)
// each implement a part of. Internal to host/loaders/.
#pragma once

#include "host/loaders/gltf_loader.h"
#include "host/loaders/gltf_nodes.h"
#include "host/scene/scene.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <tiny_gltf.h>

#include <filesystem>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace spw {

// Where each embedded image's encoded bytes lie (in a buffer in a file, gltf_sources.h; in memory
// for a data: URI), per image; the pixels are left to OpenImageIO's texture cache, which reads an
// image file itself.
using ImageBytes = std::map<int, std::shared_ptr<const EmbeddedImage>>;

class GltfReader {
  public:
    GltfReader(const std::string& path, Scene& scene)
        : path_(path), dir_(std::filesystem::path(path).parent_path()), scene_(scene) {}

    // The whole file as the scene: its camera (or one framing it), its lights (or a uniform
    // environment).
    void readScene();

    // The file's meshes and lights placed by each of `transforms` into a scene whose camera is
    // set; every mesh takes `shader` where it is >= 0, else the file's materials, appended.
    void readObject(const std::vector<glm::dmat4>& transforms, int shader);

  private:
    void read(const std::vector<glm::dmat4>& transforms, bool takesCamera);

    enum class Pass { Camera, Geometry };

    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
        throw SceneError(path_, 0, (pointer.empty() ? "" : pointer + ": ") + message);
    }
    void warn(const std::string& message) {
        if (warned_.insert(message).second) scene_.warnings.push_back(path_ + ": " + message);
    }
    // A warning about one part of the file (`subject`: "material 3 (Steel)"), said once when the
    // file is read, naming every part it applies to: "material 0, material 3 and 37 more: ...".
    void warnOf(const std::string& subject, const std::string& message);
    void sayWarningsOf();

    void parse();

    void checkExtensions();

    // The node's local transform: its matrix, or translation x rotation x scale.
    glm::dmat4 finite(const glm::dmat4& m, const std::string& at) const;

    void visit(int index, const glm::dmat4& parent, const std::string& at, Pass pass, int depth);

    void readCamera(int index, const glm::dmat4& world, const std::string& at);

    // The camera at `world`'s origin, looking along its -Z with +Y up (scale taken out).
    void placeCamera(const glm::dmat4& world, double yfov, double aspect);

    // Without a camera: one on the scene's +Z side looking at the centre of its bounds, far
    // enough back that a 40-degree vertical field of view holds the bounding sphere.
    void frameBounds();
    void include(const glm::dvec3& p);

    // A file without punctual lights is lit by a uniform white environment (radiance 1, as
    // viewers light an asset) unless its emissive meshes light it alone: their power at least
    // kEmittersLightAlone of the environment's at the scene's size. Dimmer emitters (the decals,
    // labels and screens of an asset made for image-based lighting) glow under the environment,
    // and a warning says so.
    void lightByDefault();

    // --- accessors -------------------------------------------------------------------------

    // Accessor `index` as `count` elements of `components` doubles each (normalized integers
    // mapped to [0, 1] or [-1, 1]), its sparse substitutions applied; every byte it reads checked
    // to lie inside its buffer.
    // Read as T: double for attributes; uint32_t for indices (`integersOnly`: unsigned integer
    // components only, as the specification asks of indices; 4 bytes a value, not 8).
    template <class T = double>
    std::vector<T> readAccessor(int index, int components, const std::string& at,
                                bool integersOnly = false) const;

    // A sparse accessor's substitutions: element indices[j] of `out` becomes values[j].
    template <class T>
    void applySparse(const tinygltf::Accessor& a, int components, const std::string& self,
                     std::vector<T>& out) const;

    // The first of `count` elements of `element` bytes at `byteOffset` in buffer view `view`,
    // and their stride; `at` (what reads them) names the error when any would lie outside.
    const unsigned char* viewBytes(int view, size_t byteOffset, size_t count, size_t element,
                                   const std::string& at, size_t& stride) const;

    static double component(const unsigned char* p, int componentType, bool norm);

    // --- meshes ----------------------------------------------------------------------------

    void readMesh(int index, const glm::dmat4& world, const std::string& at);

    // Every mesh the node graph placed (placements_), once it is all walked: a mesh placed once
    // is read into world space; one placed more often is read once, in its own frame, as a
    // prototype, and each placement is an instance of it (an emissive one too: SceneLights makes
    // its emitters per instance).
    void placeMeshes();
    // Mesh `index` read in its own frame as a new prototype: its index, or -1 when it has no
    // triangles.
    int readPrototype(int index, const std::string& at);

    void readPrimitive(const tinygltf::Primitive& prim, const glm::dmat4& world,
                       const std::string& at, const std::string& name);

    // NORMAL, turned into world space (the inverse transpose); where one is zero or not finite,
    // none (the faces' own normals).
    void readNormals(const tinygltf::Primitive& prim, const glm::dmat4& world, size_t vertices,
                     const std::string& at, Mesh& m);

    // TEXCOORD_n, n the set the mesh's material reads (uvSetOf_), its v turned to run up: glTF's v
    // runs down the image, Spillway's (OBJ's) up.
    void readTextureCoordinates(const tinygltf::Primitive& prim, size_t vertices,
                                const std::string& at, Mesh& m);

    // COLOR_0 (RGB, or RGBA whose alpha is not read): per-vertex factors of the base colour,
    // clamped to [0, 1]. Not read where a YAML shader overrides the file's materials.
    void readColours(const tinygltf::Primitive& prim, size_t vertices, const std::string& at,
                     Mesh& m) const;

    // The primitive's triangles (a list, strip or fan; without indices, its vertices in order),
    // each index checked against the vertex count; zero-area triangles counted, not kept.
    void readTriangles(const tinygltf::Primitive& prim, int mode, const glm::dmat4& world,
                       size_t vertices, const std::string& at, Mesh& m) const;

    // --- materials -------------------------------------------------------------------------

    // glTF's default material: white, metallic 1, roughness 1.
    static Shader defaultShader();

    int shaderFor(int material, const std::string& at);

    Shader readMaterial(int index);

    // A specular-glossiness material's images converted to metallic-roughness texel by texel
    // (gltf_specular_glossiness.cpp): its base colour (RGBA, sRGB) and metallic-roughness
    // (linear) images, PNGs held in memory, in place of the file's.
    struct ConvertedImages {
        Texture base, metallicRoughness;
    };

    // The material's images: base colour (and its alpha, for MASK), metallic-roughness and
    // normal map, and what is not rendered of the rest; the base colour and metallic-roughness
    // images `converted`'s where it is not null.
    void readImages(const tinygltf::Material& mat, Shader& s, const std::string& at,
                    const std::string& name, const ConvertedImages* converted);

    // KHR_materials_transmission with KHR_materials_ior: a material that transmits all the light
    // (transmissionFactor 1) and is no metal is glass, a Dielectric of that ior (1.5) and GGX
    // alpha roughness^2 (smooth below kGgxSmoothAlpha), as Blender's importer and Cycles render
    // it: a refracting solid, not the specification's thin wall, its base colour tinting what it
    // refracts. Transmitting part of it (0 < transmissionFactor < 1, a transmissionTexture, or a
    // metallic above 0), a TransmissiveMetallicRoughness: that glass mixed with the opaque
    // material by the factor times 1 - metallic (shared/transmissive_metallic_roughness.h).
    void readTransmission(const tinygltf::Material& mat, Shader& s, const std::string& at,
                          const std::string& name);
    // KHR_materials_volume on glass, whole or partial: attenuationColor left after
    // attenuationDistance, as the medium's absorption coefficient -ln(colour) / distance
    // (ShaderParams::absorption). thicknessFactor 0 (thin-walled) absorbs nothing, and says so.
    void readVolume(const tinygltf::Material& mat, Shader& s, const std::string& at,
                    const std::string& name);
    // KHR_materials_clearcoat: a material with a coat of weight clearcoatFactor > 0 is a
    // CoatedMetallicRoughness shader (shared/coated_metallic_roughness.h), its coat's GGX alpha
    // clearcoatRoughnessFactor^2, each factor times its image where it has one; the coat's normal
    // map is warned about and not rendered.
    // KHR_materials_sheen: a material with a sheen of colour above 0 is a SheenMetallicRoughness
    // shader (shared/sheen_metallic_roughness.h), colour and roughness each times its image where
    // it has one.
    void readSheen(const tinygltf::Material& mat, Shader& s, const std::string& at,
                   const std::string& name);
    // KHR_materials_specular: the dielectric reflection's weight and F0 colour, each times its
    // image where the material is no clear coat or sheen (those take the hit's extension values;
    // there the images are warned about and the factors alone rendered).
    void readSpecular(const tinygltf::Material& mat, Shader& s, const std::string& at,
                      const std::string& name);
    void readClearcoat(const tinygltf::Material& mat, Shader& s, const std::string& at,
                       const std::string& name);
    // SPILLWAY_materials_principled (the Blender add-on's): Blender's Principled BSDF factors
    // beyond glTF's core (specular, specularTint, sheen, sheenTint, clearcoat, clearcoatRoughness,
    // each in [0, 1], Blender's defaults where absent) make an opaque material a Principled shader
    // (shared/principled.h) of the core's base colour, metallic and roughness and their images;
    // they replace the clear coat, sheen and specular extensions' factors, whose images are warned
    // about. On glass it is warned about and the glass kept.
    void readPrincipled(const tinygltf::Material& mat, Shader& s, const std::string& at,
                        const std::string& name);
    // KHR_materials_pbrSpecularGlossiness (older assets' workflow), where `mat` has it: the
    // material converted to metallic-roughness into `converted` (returned), as the extension's
    // converters do (gltf_specular_glossiness.cpp), and where it has a specularGlossinessTexture,
    // or a diffuseTexture the conversion is not linear in, its images converted into `images`;
    // else `mat` itself.
    const tinygltf::Material& readSpecularGlossiness(const tinygltf::Material& mat,
                                                     const std::string& at, const std::string& name,
                                                     tinygltf::Material& converted,
                                                     std::optional<ConvertedImages>& images);
    // The extension's factors (diffuse RGBA).
    struct SpecularGlossiness {
        glm::vec4 diffuse{1.0f};
        vec3 specular{1.0f};
        double glossiness = 1.0;
    };
    // Its images and factors, texel by texel: the bake at the larger image's size, read through
    // the specularGlossinessTexture's coordinates, transform and sampler (the diffuseTexture's
    // where it has none). `at` is the material's JSON pointer.
    ConvertedImages convertSpecularGlossiness(const tinygltf::Value& sg, const std::string& at,
                                              const std::string& name,
                                              const SpecularGlossiness& factors);
    // The number at `key` of extension object `ext` (its JSON pointer `at`), or `fallback` where
    // it is absent; refused unless it is a finite number in [lo, hi] (hi may be HUGE_VAL).
    double extensionNumber(const tinygltf::Value& ext, const char* key, double fallback, double lo,
                           double hi, const std::string& at) const;
    // The three numbers at `key` of extension object `ext` (a colour factor), or `fallback`
    // where it is absent; refused unless an array of three finite numbers in [0, hi] (hi may be
    // HUGE_VAL; values above 1000 are taken as 1000).
    vec3 extensionColour(const tinygltf::Value& ext, const char* key, vec3 fallback, double hi,
                         const std::string& at) const;
    // The Dielectric model's least index of refraction.
    static constexpr double kMinGlassIor = 1.01;

    // emissiveFactor times KHR_materials_emissive_strength's strength, times emissiveTexture's
    // image (sRGB) where the material has one and the factor is not black.
    void readEmission(const tinygltf::Material& mat, Shader& s, const std::string& at,
                      const std::string& name);

    double unit(double x, const std::string& at) const {
        if (!(x >= 0.0 && x <= 1.0)) fail(at, "must lie in [0, 1]");
        return x;
    }

    // The base colour's image `picture`, times the factor: Layered(upper: image, lower: 0,
    // mask: factor).
    void baseColourTexture(const Texture& picture, Shader& s);

    // alphaMode MASK: a cut-out where baseColorFactor's alpha times the base colour image's
    // (`base`, or none) alpha channel (1 where it has none) is below alphaCutoff. A factor that
    // decides alone is no cut-out at all (at least the cutoff) or hides the whole surface.
    // BLEND: that alpha as stochastic transparency (Cutout::stochastic).
    void readCutout(const tinygltf::Material& mat, Shader& s, const std::string& at,
                    const Texture* base);

    // A texture reference's image, as a Standard texture with its KHR_texture_transform: read
    // from memory where the file embeds it (checked readable now), else from beside the file.
    // The coordinate set it names (texCoord, or the transform's override) joins uvSetsRead_.
    template <class Info> // tinygltf::TextureInfo, NormalTextureInfo
    Texture imageTexture(const Info& info, const std::string& where, const std::string& what);
    // Image `source` of the file opened for its header and pixels (refused unless a PNG or a
    // JPEG, whole, that OpenImageIO reads): from its bytes where the file embeds it, else from
    // beside the file; its path (and bytes) set in `picture`.
    struct OpenedImage {
        std::unique_ptr<OIIO::Filesystem::IOProxy> proxy; // an embedded image's reader, for `in`
        std::unique_ptr<OIIO::ImageInput> in;
    };
    OpenedImage openImage(int source, Texture& picture) const;
    // A material extension's texture `key` of object `ext` (at JSON pointer `where`): its image
    // as a Standard texture of the scene read from `channel` on (3: alpha alone), as colour (sRGB)
    // or as data; its index, or -1 where `ext` has none.
    int extensionTexture(const tinygltf::Value& ext, const char* key, int channel, bool colour,
                         const std::string& where, const std::string& what);
    // The texture reference ext[key], at `at`, checked for its form (an object with an index).
    tinygltf::TextureInfo extensionTextureInfo(const tinygltf::Value& ext, const char* key,
                                               const std::string& at) const;
    // The texture references `keys` of an extension whose images are not rendered (a factor of
    // 0, a model that does not take them), checked as rendered ones are: their form, and that
    // they name a texture of the file. A factor of 0 does not make a reference to nothing valid.
    void checkUnusedTextures(const tinygltf::Value& ext, std::initializer_list<const char*> keys,
                             const std::string& where) const;

    // OpenImageIO's error after a failed open, as ": why" (or nothing). Asking also clears it:
    // OpenImageIO keeps it per thread until asked, and reports it at exit otherwise.
    static std::string imageError();

    // A sampler's wrap modes; its filters are always bilinear and trilinear across MIP levels,
    // and a NEAREST one is warned about.
    void readSampler(const tinygltf::Sampler& s, const std::string& at, const std::string& what,
                     Texture& picture);

    // KHR_texture_transform on a texture reference: T(offset) R(rotation) S(scale) of glTF's
    // texture coordinates, R turning them as the extension's reference model does (the image
    // clockwise as seen upright), written for Spillway's (v = 1 - glTF's v) as F M F, F that
    // flip.
    // Returns the extension's texCoord override, or -1.
    template <class Info>
    int readTextureTransform(const Info& info, const std::string& where, Texture& picture);

    // The texture coordinate set material `material`'s images read, from uvSetsRead_ once they
    // are all read: the one they name; where they name several, the first one's, the base
    // colour's where it has one (warned).
    int chooseUvSet(int material);

    // The highest TEXCOORD_n a texture may name (Blender writes at most 8 sets).
    static constexpr int kMaxUvSet = 255;

    // --- lights ----------------------------------------------------------------------------

    void readLight(const GltfNode& n, const glm::dmat4& world, const std::string& at);

    void warnUnrendered() {
        if (!model_.animations.empty()) warn("has animations: rendered at rest");
        if (model_.scenes.size() > 1) warn("has more than one scene: the default one rendered");
        sayWarningsOf();
    }

    std::string path_;
    std::filesystem::path dir_;
    Scene& scene_;
    tinygltf::Model model_;
    std::vector<GltfNode> nodes_; // the file's nodes (gltf_nodes.h), until the graph is read
    ImageBytes embedded_;
    std::set<std::string> warned_;
    // warnOf's messages in the order first said, each with the parts it was said of.
    std::vector<std::pair<std::string, std::vector<std::string>>> warningsOf_;
    std::set<int> onPath_;
    std::vector<int> shaderOf_;
    // Per shader made from the file: the TEXCOORD_n its meshes' texture coordinates are read from.
    // A mesh carries one set, and every image of its material is looked up in it.
    std::map<int, int> uvSetOf_;
    // The sets the images of the material being read name, the base colour's first.
    std::vector<int> uvSetsRead_;
    glm::dvec3 lo_{0.0}, hi_{0.0}; // the bounds of every position and point light read
    bool bounded_ = false;
    bool cameraFound_ = false, cameraSeen_ = false;
    int shaderOverride_ = -1;
    // The meshes the node graph places, in the order it names them (visit), read by placeMeshes.
    // (A million nodes make a million of these: the node's index, not its pointer's text.)
    struct Placement {
        int mesh;
        int node;
        glm::dmat4 world;
        std::string at() const { return "/nodes/" + std::to_string(node) + "/mesh"; }
    };
    std::vector<Placement> placements_;
    // While a prototype's meshes are read: its index (their positions stay in the mesh's frame).
    int prototype_ = -1;
    size_t instancedEmitters_ = 0; // emissive triangles counted once per instance (placeMeshes)
};

} // namespace spw
