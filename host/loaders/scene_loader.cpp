// The YAML scene loader: docs/scene-format.md made executable. Every value is checked for type and
// range where it is read, and every error names the file and line of the offending node.
#include "host/loaders/scene_loader.h"
#include "host/image/image_io.h"
#include "host/image/jpeg_check.h"
#include "host/loaders/gltf_loader.h"
#include "host/loaders/light_loader.h"
#include "host/loaders/obj_mesh.h"
#include "host/loaders/settings_loader.h"
#include "host/loaders/yaml_reader.h"
#include "host/scene/scene.h"
#include "host/scene/surface_models.h"
#include "shared/metallic_roughness.h"

#include <OpenImageIO/imageio.h>
#include <glm/gtc/matrix_transform.hpp>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace spw {
namespace {

using namespace scene_file;

// Texture trees. A YAML anchor may be used many times and even inside itself: a node seen
// before is shared (one Scene::textures entry, read once), a node used inside itself is a cycle,
// and the tree's depth and size are bounded, so no file makes the loader recurse or multiply
// without end.
class TextureReader {
  public:
    TextureReader(const Reader& rd, const fs::path& dir, Scene& scene)
        : rd_(rd), dir_(dir), scene_(scene) {}

    int read(const YAML::Node& n, int depth = 1) {
        if (depth > kMaxTextureDepth)
            rd_.fail(n,
                     "textures nest deeper than " + std::to_string(kMaxTextureDepth) + " levels");
        // yaml-cpp has no node identity but is(); nodes sharing a position in the file are the
        // only candidates for being the same node.
        std::vector<Seen>& atPos = seen_[n.Mark().pos];
        for (const Seen& e : atPos)
            if (e.node.is(n)) {
                if (e.index < 0)
                    rd_.fail(n,
                             "texture contains itself (a YAML alias used inside its own anchor)");
                return e.index;
            }
        atPos.push_back({n, -1});
        const size_t slot = atPos.size() - 1;
        const int index = readNode(n, depth);
        seen_[n.Mark().pos][slot].index = index;
        return index;
    }

  private:
    struct Seen {
        YAML::Node node;
        int index; // -1 while its subtree is being read
    };

    int readNode(const YAML::Node& n, int depth) {
        const Reader& rd = rd_;
        rd.checkKeys(n, "texture",
                     {"type", "colour", "string", "filename", "upper", "lower", "mask"});
        if (!n["type"]) rd.fail(n, "texture needs a type (Constant, Standard or Layered)");
        std::string t = rd.string(n["type"], "texture type");
        Texture tex;
        tex.line = n.Mark().line + 1;
        auto only = [&](const std::vector<std::string>& keys) {
            rd.checkKeys(n, t + " texture", keys);
        };
        if (t == "Constant") {
            only({"type", "colour"});
            tex.type = TextureType::Constant;
            if (n["colour"]) tex.colour = rd.vec<3>(n["colour"], "texture colour", 0.0, 1.0);
        } else if (t == "Standard") {
            only({"type", "string", "filename"});
            tex.type = TextureType::Standard;
            YAML::Node f = n["string"] ? n["string"] : n["filename"];
            if (!f) rd.fail(n, "Standard texture needs 'string' (or 'filename'): the image file");
            fs::path p = dir_ / rd.string(f, "texture file");
            if (!fs::is_regular_file(p))
                rd.fail(f, "texture file '" + p.string() + "' does not exist");
            tex.path = fs::absolute(p).lexically_normal().string();
            checkImage(f, tex.path);
        } else if (t == "Layered") {
            only({"type", "upper", "lower", "mask"});
            tex.type = TextureType::Layered;
            for (const char* k : {"upper", "lower", "mask"})
                if (!n[k]) rd.fail(n, std::string("Layered texture needs '") + k + "'");
            tex.upper = read(n["upper"], depth + 1);
            tex.lower = read(n["lower"], depth + 1);
            tex.mask = read(n["mask"], depth + 1);
        } else {
            rd.fail(n["type"], "unknown texture type '" + t + "' (Constant, Standard or Layered)");
        }
        if (scene_.textures.size() >= size_t(kMaxTextures))
            rd.fail(n, "more than " + std::to_string(kMaxTextures) + " textures");
        scene_.textures.push_back(tex);
        return int(scene_.textures.size()) - 1;
    }

    // A file that is not an image is the scene's error, found now rather than mid-render. Only
    // the header is read: the pixels stay lazy, for the texture system.
    void checkImage(const YAML::Node& at, const std::string& path) const {
        for (const std::string& why : {exrHeaderProblem(path), jpegFileCutShort(path)})
            if (!why.empty()) rd_.fail(at, "texture file " + why);
        auto in = OIIO::ImageInput::open(path);
        if (!in) {
            std::string why = OIIO::geterror();
            while (!why.empty() && (why.back() == '\n' || why.back() == '\r'))
                why.pop_back();
            rd_.fail(at,
                     "texture file '" + path + "' is not an image OpenImageIO can read: " + why);
        }
        const OIIO::ImageSpec& spec = in->spec();
        if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
            rd_.fail(at, "texture file '" + path + "' holds no pixels");
        in->close();
    }

    const Reader& rd_;
    const fs::path& dir_;
    Scene& scene_;
    std::map<std::size_t, std::vector<Seen>> seen_;
};

// The metallic-roughness models' keys (shared/metallic_roughness.h,
// shared/coated_metallic_roughness.h), the Dielectric's absorption, and the Principled's keys
// (shared/principled.h), whose defaults are Blender's.
void readGltfParams(const Reader& rd, const YAML::Node& n, uint takes, ShaderParams& p) {
    const bool blender = (takes & kTakesPrincipled) != 0u;
    auto unitKey = [&](const char* key, float fallback) {
        return n[key] ? float(rd.number(n[key], key, 0.0, 1.0)) : fallback;
    };
    // Glass that transmits part of the light is no metal unless told.
    if (takes & kTakesMetallic)
        p.metallic = unitKey("metallic", blender || (takes & kTakesTransmission) ? 0.0f : 1.0f);
    if (takes & kTakesRoughness) {
        const float r = unitKey("roughness", blender ? 0.5f : 1.0f);
        // The transmissive model's glass takes alpha as it is (smooth below kGgxSmoothAlpha).
        p.alpha = takes & kTakesTransmission ? r * r : gltfAlpha(r);
    }
    if (takes & kTakesTransmission) p.transmission = unitKey("transmission", 1.0f);
    if (n["absorption"]) p.absorption = rd.vec<3>(n["absorption"], "absorption", 0.0, 1e30);
    if (takes & kTakesCoat) {
        p.coat = unitKey("coat", blender ? 0.0f : 1.0f);
        p.coatAlpha = gltfAlpha(unitKey("coat roughness", blender ? 0.03f : 0.0f));
    }
    if (takes & kTakesSheen) {
        p.sheenColour =
            n["sheen colour"] ? rd.vec<3>(n["sheen colour"], "sheen colour", 0.0, 1.0) : vec3(1.0f);
        p.sheenRoughness = unitKey("sheen roughness", 0.5f);
    }
    if (blender) {
        p.specular = unitKey("specular", 0.5f);
        p.specularTint = unitKey("specular tint", 0.0f);
        p.sheen = unitKey("sheen", 0.0f);
        p.sheenTint = unitKey("sheen tint", 0.5f);
    } else if (n["specular"] || n["specular colour"]) {
        p.flags |= kShaderSpecular;
        p.specular = unitKey("specular", 1.0f);
        p.specularColour = n["specular colour"]
                               ? rd.vec<3>(n["specular colour"], "specular colour", 0.0, 1000.0)
                               : vec3(1.0f);
    }
}

// A shader: `type` names a registered surface model (host/scene/surface_models.h), or Emissive
// (the Null model with emission required). Every model takes `emission` and `two sided`; the
// other keys are the ones its registry line names, each read here with its one range.
void readShader(const Reader& rd, const YAML::Node& n, TextureReader& textures, Scene& scene) {
    std::string types = "Emissive";
    for (const SurfaceModelInfo& m : kSurfaceModels)
        types += std::string(", ") + m.name;
    types = "(" + types + ")";
    if (!n.IsMap() || !n["type"]) rd.fail(n, "shader needs a type " + types);
    // YAML reads a plain `Null` (like `null` and `~`) as the null value, not as a string: the
    // format's shader type Null is written that way, so a null type means Null.
    std::string t = n["type"].IsNull() ? "Null" : rd.string(n["type"], "shader type");
    const SurfaceModelInfo* model = t == "Emissive" ? surfaceModel(kModelNull) : nullptr;
    for (const SurfaceModelInfo& m : kSurfaceModels)
        if (t == m.name) model = &m;
    if (!model) rd.fail(n["type"], "unknown shader type '" + t + "' " + types);

    std::vector<std::string> keys = {"type", "emission", "two sided"};
    const uint takes = model->params;
    for (auto [bit, key] : {std::pair{kTakesReflectance, "reflectance"},
                            {kTakesColour, "colour"},
                            {kTakesTexture, "texture"},
                            {kTakesAlpha, "alpha"},
                            {kTakesIor, "ior"},
                            {kTakesMetallic, "metallic"},
                            {kTakesRoughness, "roughness"},
                            {kTakesAbsorption, "absorption"},
                            {kTakesCoat, "coat"},
                            {kTakesCoat, "coat roughness"},
                            {kTakesSpecular, "specular"},
                            {kTakesSpecular, "specular colour"},
                            {kTakesTransmission, "transmission"},
                            {kTakesSheen, "sheen colour"},
                            {kTakesSheen, "sheen roughness"},
                            {kTakesPrincipled, "specular"},
                            {kTakesPrincipled, "specular tint"},
                            {kTakesPrincipled, "sheen"},
                            {kTakesPrincipled, "sheen tint"}})
        if (takes & bit) keys.push_back(key);
    rd.checkKeys(n, t + " shader", keys);
    if (t == "Emissive" && !n["emission"]) rd.fail(n, "Emissive shader needs 'emission'");

    Shader s;
    s.typeName = t;
    s.line = n.Mark().line + 1;
    ShaderParams& p = s.params;
    p.model = model->model;
    p.colour = vec3(takes & kTakesPrincipled ? 0.8f : 1.0f); // Blender's base colour
    p.reflectance = 1.0f;
    p.emission = vec3(0.0f);
    p.ior = 1.5f;
    p.alpha = 0.0f;
    if (n["reflectance"])
        p.reflectance = float(rd.number(n["reflectance"], "reflectance", 0.0, 1.0));
    if (n["colour"] && n["texture"])
        rd.fail(n["texture"], t + " takes colour or texture, not both");
    if (n["colour"]) p.colour = rd.vec<3>(n["colour"], "colour", 0.0, 1.0);
    if (n["texture"]) {
        s.texture = textures.read(n["texture"]);
        p.flags |= kShaderTextured;
    }
    if (n["ior"]) p.ior = float(rd.number(n["ior"], "ior", 1.01, 10.0));
    if (n["alpha"]) p.alpha = float(rd.number(n["alpha"], "alpha", 0.0, 1.0));
    readGltfParams(rd, n, takes, p);
    if (n["emission"]) p.emission = rd.vec<3>(n["emission"], "emission", 0.0, kMaxRadiance);
    if (n["two sided"] && rd.boolean(n["two sided"], "two sided")) p.flags |= kShaderTwoSided;
    scene.shaders.push_back(s);
}

struct PendingObject {
    YAML::Node node;
    int shader;
    int line;
};

// A glTF file placed as an object: read once every YAML shader is (its materials follow them).
struct PendingGltf {
    std::string path;
    std::vector<glm::dmat4> transforms; // one per placement (an object's `instances:`)
    int shader;                         // -1: the file's own materials
};

// An OBJ placed by `instances:`: read once, in its own frame (Scene::meshes[mesh]), and made a
// prototype once the shaders are known.
struct PendingInstances {
    size_t mesh;
    std::string path;
    std::vector<glm::dmat4> transforms;
    int line; // the `instances:` key's
};

// The object's transform, or with `instances:` that transform after each instance's own.
std::vector<glm::dmat4> placements(const Reader& rd, const YAML::Node& n) {
    const glm::dmat4 xf = readTransform(rd, n, "object", true);
    if (!n["instances"]) return {xf};
    const YAML::Node& list = n["instances"];
    if (!list.IsSequence() || list.size() == 0)
        rd.fail(list, "instances must be a list of transforms ({translation, rotation, scale})");
    std::vector<glm::dmat4> out;
    for (const YAML::Node& e : list) {
        if (!e.IsMap()) rd.fail(e, "an instance is a map of translation, rotation and scale");
        rd.checkKeys(e, "instance", {"translation", "rotation", "scale"});
        out.push_back(xf * readTransform(rd, e, "instance", true));
    }
    return out;
}

void readObject(const Reader& rd, const YAML::Node& n, const fs::path& dir, Scene& scene,
                std::vector<PendingObject>& pending, std::vector<PendingGltf>& gltf,
                std::vector<PendingInstances>& instanced) {
    if (!n.IsMap()) rd.fail(n, "object must be a map of keys to values");
    rd.checkKeys(n, "object",
                 {"type", "filename", "translation", "rotation", "scale", "shader", "instances"});
    std::string t = n["type"] ? rd.string(n["type"], "object type") : "Polygon";
    if (t != "Polygon" && t != "Gltf")
        rd.fail(n["type"], "unknown object type '" + t + "' (Polygon, Gltf)");
    const bool isGltf = t == "Gltf";
    if (!n["filename"])
        rd.fail(n, std::string("object needs a filename (") +
                       (isGltf ? "a .gltf or .glb file)" : "an OBJ file)"));
    fs::path p = dir / rd.string(n["filename"], "object filename");
    if (!fs::is_regular_file(p))
        rd.fail(n["filename"], "object file '" + p.string() + "' does not exist");
    if (isGltf && !isGltfPath(p.string()))
        rd.fail(n["filename"], "a Gltf object's file ends in .gltf or .glb");
    int shader = n["shader"] ? int(rd.integer(n["shader"], "object shader", 0, 1 << 30)) : 0;
    const std::vector<glm::dmat4> xf = placements(rd, n);
    if (isGltf) {
        gltf.push_back({p.string(), xf, n["shader"] ? shader : -1});
        if (n["shader"]) pending.push_back({n, shader, n["shader"].Mark().line + 1});
        return;
    }
    const bool instances = bool(n["instances"]);
    Mesh mesh = loadObjMesh(p.string(), instances ? glm::dmat4(1.0) : xf[0],
                            instances ? glm::dvec3(0.0) : scene.origin, rd.file(),
                            n["filename"].Mark().line + 1);
    if (instances)
        instanced.push_back({scene.meshes.size(), p.string(), xf, n["instances"].Mark().line + 1});
    scene.inputs.push_back(p.string());
    mesh.shader = shader;
    scene.meshes.push_back(std::move(mesh));
    // A bad index is reported at the `shader:` value, or at the object when it has none.
    pending.push_back({n, shader, (n["shader"] ? n["shader"] : n).Mark().line + 1});
}

} // namespace

namespace {

std::string readSceneText(const std::string& path) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec) throw SceneError(path, 0, "cannot open the scene file: " + ec.message());
    if (fs::is_directory(st)) throw SceneError(path, 0, "is a folder, not a scene file");
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw SceneError(path, 0,
                         std::string("cannot open the scene file: ") + std::strerror(errno));
    std::stringstream text;
    text << in.rdbuf();
    if (in.bad())
        throw SceneError(path, 0,
                         std::string("cannot read the scene file: ") + std::strerror(errno));
    return text.str();
}

// The scene file's YAML, or a SceneError naming where it is malformed.
YAML::Node parseYaml(const std::string& path, const std::string& text) {
    try {
        return YAML::Load(text);
    } catch (const YAML::DeepRecursion& e) {
        throw SceneError(path, e.mark.line + 1,
                         "YAML nests deeper than yaml-cpp's limit of " +
                             std::to_string(e.depth() - 1) + " levels");
    } catch (const YAML::ParserException& e) {
        throw SceneError(path, e.mark.line + 1, "YAML syntax error: " + e.msg);
    } catch (const YAML::Exception& e) {
        throw SceneError(path, e.mark.line + 1, "YAML error: " + e.msg);
    }
}

// The top level's entries into a scene: the camera first, then the rest in file order, then
// the quad lights' meshes after the objects'.
class SceneReader {
  public:
    SceneReader(const Reader& rd, const fs::path& dir, Scene& scene)
        : rd_(rd), dir_(dir), scene_(scene), textures_(rd, dir, scene) {}

    void readEntries(const YAML::Node& root) {
        // The camera first, wherever it stands in the file: everything else is placed relative
        // to it.
        for (auto it = root.begin(); it != root.end(); ++it)
            if (it->first.IsScalar() && it->first.Scalar() == "camera") {
                scene_.origin = readCamera(rd_, it->second, scene_.camera);
                break;
            }
        for (auto it = root.begin(); it != root.end(); ++it)
            // it->second is a handle: a reference would dangle (the iterator returns a proxy).
            readEntry(it->first, it->second);
    }

    void finish(const YAML::Node& root);

  private:
    // The OBJ objects placed by `instances:`, once their shaders are known (PendingInstances).
    void placeInstances();
    // The glTF objects, a file placed by several objects of one shader read once, as instances.
    void appendGltfObjects();

    void readEntry(const YAML::Node& keyNode, const YAML::Node& v) {
        const std::string key = keyNode.as<std::string>();
        const bool single = key == "image" || key == "settings" || key == "camera" ||
                            key == "filter" || key == "sampler";
        if (single && !seenOnce_.insert(key).second)
            rd_.fail(keyNode, "'" + key + "' may appear only once");
        auto each = [&](const char* plural, const std::function<void(const YAML::Node&)>& fn) {
            if (key == plural && !v.IsSequence())
                rd_.fail(v, "'" + std::string(plural) + "' must be a list");
            if (v.IsSequence()) {
                for (const YAML::Node& e : v)
                    fn(e);
            } else {
                fn(v);
            }
        };
        if (key == "image")
            readImage(rd_, v, scene_.image);
        else if (key == "settings")
            readSettings(rd_, v, scene_.settings);
        else if (key == "camera")
            return; // read first
        else if (key == "filter")
            readFilter(rd_, v, scene_.filter);
        else if (key == "sampler")
            scene_.sampler = readSampler(rd_, v);
        else if (key == "object" || key == "objects")
            each("objects", [&](const YAML::Node& e) {
                roomFor(e, 0, 1);
                readObject(rd_, e, dir_, scene_, pending_, gltf_, instanced_);
            });
        else if (key == "shader" || key == "shaders")
            each("shaders", [&](const YAML::Node& e) {
                roomFor(e, 1, 0);
                readShader(rd_, e, textures_, scene_);
            });
        else if (key == "light" || key == "lights")
            each("lights", [&](const YAML::Node& e) { readLight(e); });
        else
            rd_.fail(keyNode,
                     "unknown entry '" + key +
                         "' (image, settings, camera, filter, sampler, object, shader, light)");
    }

    void readLight(const YAML::Node& e) {
        if (!e.IsMap() || !e["type"]) rd_.fail(e, "light needs a type (" + lightTypeList() + ")");
        const std::string t = rd_.string(e["type"], "light type");
        const EmitterKindInfo* kind = emitterKindNamed(t);
        if (!kind) rd_.fail(e["type"], "unknown light type '" + t + "' (" + lightTypeList() + ")");
        if (kind->kind == kEmitterTriangle) {
            roomFor(e, 1, 1);
            lightShaders_.push_back(readQuadLight(rd_, e, scene_.origin, lightMeshes_));
        } else if (kind->kind == kEmitterEnvironment) {
            if (scene_.environment)
                rd_.fail(e, "a second Environment light (the first is at line " +
                                std::to_string(scene_.environment->line) + ")");
            scene_.environment = readEnvironment(rd_, e, dir_);
        } else {
            scene_.punctualLights.push_back(readPunctualLight(rd_, e, scene_.origin, *kind));
        }
    }

    // The hit key's limits (kMaxShaders, kMaxObjects), checked before each element that adds
    // `shaders` shaders and `objects` objects (a light adds one of each): the error names it.
    void roomFor(const YAML::Node& e, size_t shaders, size_t objects) const {
        if (scene_.shaders.size() + lightShaders_.size() + shaders > size_t(kMaxShaders))
            rd_.fail(e,
                     "more than " + std::to_string(kMaxShaders) + " shaders (a light counts one)");
        if (scene_.meshes.size() + lightMeshes_.size() + objects > size_t(kMaxObjects))
            rd_.fail(e,
                     "more than " + std::to_string(kMaxObjects) + " objects (a light counts one)");
    }

    const Reader& rd_;
    const fs::path& dir_;
    Scene& scene_;
    TextureReader textures_;
    std::vector<PendingObject> pending_;
    std::vector<PendingGltf> gltf_;
    std::vector<PendingInstances> instanced_;
    std::vector<Mesh> lightMeshes_;
    std::vector<Shader> lightShaders_;
    std::set<std::string> seenOnce_;
};

void SceneReader::placeInstances() {
    size_t emitters = 0; // emissive triangles, once per instance, over every object's instances
    for (const PendingInstances& o : instanced_) {
        Mesh& mesh = scene_.meshes[o.mesh];
        Prototype proto;
        proto.name = mesh.name;
        proto.meshes = {uint(o.mesh)};
        proto.lo = vec3(std::numeric_limits<float>::max());
        proto.hi = vec3(-std::numeric_limits<float>::max());
        for (const vec3& p : mesh.positions) {
            proto.lo = glm::min(proto.lo, p);
            proto.hi = glm::max(proto.hi, p);
        }
        mesh.prototype = int(scene_.prototypes.size());
        scene_.prototypes.push_back(std::move(proto));
        if (scene_.instances.size() + o.transforms.size() > size_t(kMaxInstances))
            rd_.fail(o.line, "more than " + std::to_string(kMaxInstances) + " instances");
        emitters += emissiveTriangles(scene_, scene_.prototypes.back()) * o.transforms.size();
        if (emitters > kMaxInstancedEmitters)
            rd_.fail(o.line, "the emissive triangles instances place, counted at each placement, "
                             "are more than " +
                                 std::to_string(kMaxInstancedEmitters));
        for (const glm::dmat4& t : o.transforms) {
            glm::dmat4 world = t;
            world[3] -= glm::dvec4(scene_.origin, 0.0);
            std::string error;
            scene_.instances.push_back(
                makeInstance(scene_.prototypes.back(), uint(mesh.prototype), world, error));
            if (!error.empty()) rd_.fail(o.line, error);
        }
    }
}

void SceneReader::appendGltfObjects() {
    std::vector<bool> done(gltf_.size(), false);
    for (size_t i = 0; i < gltf_.size(); ++i) {
        if (done[i]) continue;
        std::vector<glm::dmat4> transforms;
        for (size_t j = i; j < gltf_.size(); ++j)
            if (gltf_[j].path == gltf_[i].path && gltf_[j].shader == gltf_[i].shader) {
                transforms.insert(transforms.end(), gltf_[j].transforms.begin(),
                                  gltf_[j].transforms.end());
                done[j] = true;
            }
        appendGltfObject(gltf_[i].path, transforms, gltf_[i].shader, scene_);
    }
}

// What can be checked only once everything is read: the objects' shaders exist, the quad
// lights' meshes follow the objects', and the camera and sample counts stay in range.
void SceneReader::finish(const YAML::Node& root) {
    const int sceneShaders = int(scene_.shaders.size());
    for (const PendingObject& o : pending_)
        if (o.shader >= sceneShaders)
            rd_.fail(o.line, "object uses shader " + std::to_string(o.shader) +
                                 " but the scene has " + std::to_string(sceneShaders) + " shader" +
                                 (sceneShaders == 1 ? "" : "s"));
    placeInstances();
    appendGltfObjects();
    if (scene_.shaders.size() + lightShaders_.size() > size_t(kMaxShaders) ||
        scene_.meshes.size() + lightMeshes_.size() > size_t(kMaxObjects))
        rd_.fail(1, "more than " + std::to_string(kMaxShaders) + " shaders or " +
                        std::to_string(kMaxObjects) +
                        " objects with the glTF files' materials and meshes");
    scene_.objectCount = int(scene_.meshes.size());
    scene_.quadLightCount = int(lightMeshes_.size());
    for (size_t i = 0; i < lightMeshes_.size(); ++i) {
        lightMeshes_[i].shader = int(scene_.shaders.size());
        scene_.shaders.push_back(lightShaders_[i]);
        scene_.meshes.push_back(std::move(lightMeshes_[i]));
    }
    const ImageSettings& img = scene_.image;
    // A ThinLens ray aims at the focal plane: its farthest corner lies within kMaxDistance too.
    if (scene_.camera.type == CameraType::ThinLens) {
        const double tx = scene_.camera.tanHalfFovX(), ty = tx * img.height / img.width;
        const double corner = scene_.camera.focalDistance * std::sqrt(1.0 + tx * tx + ty * ty);
        if (!(corner <= kMaxDistance)) {
            const YAML::Node cam = root["camera"];
            rd_.fail(cam["focal distance"] ? cam["focal distance"] : cam,
                     "the focal plane's corners lie " + Reader::fmt(corner) +
                         " units from the camera; Spillway renders within " +
                         Reader::fmt(kMaxDistance) + " units of it");
        }
    }
    if ((unsigned long long)img.width * img.height * img.samplesPerIteration() > 0xFFFFFFFFull)
        rd_.fail(1,
                 "width x height x sample base^2 exceeds 2^32 - 1 samples per iteration; lower the "
                 "sample base and raise iterations");
}

} // namespace

namespace {
// A YAML scene file (docs/scene-format.md).
Scene loadYamlScene(const std::string& path) {
    Scene scene;
    scene.file = path;
    const Reader rd(path);
    const YAML::Node root = parseYaml(path, readSceneText(path));
    if (root.IsNull()) return scene; // an empty file is an empty scene: black
    if (!root.IsMap()) rd.fail(root, "a scene is a map of entries (image, camera, object, ...)");
    const fs::path dir = fs::path(path).parent_path();
    SceneReader reader(rd, dir, scene);
    try {
        reader.readEntries(root);
    } catch (const YAML::Exception& e) {
        throw SceneError(path, e.mark.line + 1, e.msg);
    }
    reader.finish(root);
    return scene;
}
} // namespace

Scene loadScene(const std::string& path) {
    Scene scene = isGltfPath(path) ? loadGltfScene(path) : loadYamlScene(path);
    for (Mesh& m : scene.meshes)
        padForSharing(m);
    return scene;
}

} // namespace spw
