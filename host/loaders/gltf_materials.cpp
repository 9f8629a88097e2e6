// GltfReader's materials (gltf_reader.h): glTF's metallic-roughness model as a MetallicRoughness
// shader, one per material, with its images (base colour and its alpha, metallic-roughness,
// normal map, emission) as textures read by OpenImageIO from the file or the bytes it embeds,
// and KHR_texture_transform.
#include "host/image/image_io.h"
#include "host/image/jpeg_check.h"
#include "host/loaders/gltf_preflight.h"
#include "host/loaders/gltf_reader.h"
#include "host/textures/embedded_reader.h"

#include "shared/metallic_roughness.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <set>

namespace spw {

namespace fs = std::filesystem;

namespace {
// glTF 2.0's image formats, from an image's first bytes: ".png", ".jpg", or "" for anything else.
std::string imageFormat(const std::string& head) {
    if (head.size() >= 8 && head.compare(0, 8, "\x89PNG\r\n\x1a\n", 8) == 0) return ".png";
    if (head.size() >= 3 && head.compare(0, 3, "\xFF\xD8\xFF", 3) == 0) return ".jpg";
    return "";
}
} // namespace

Shader GltfReader::defaultShader() {
    Shader s;
    s.typeName = "MetallicRoughness";
    s.params.model = kModelMetallicRoughness;
    s.params.colour = vec3(1.0f);
    s.params.reflectance = 1.0f;
    s.params.metallic = 1.0f;
    s.params.alpha = gltfAlpha(1.0f);
    s.params.ior = 1.5f;
    return s;
}

int GltfReader::shaderFor(int material, const std::string& at) {
    if (shaderOverride_ >= 0) return shaderOverride_;
    if (material >= int(model_.materials.size()))
        fail(at, "names material " + std::to_string(material) + " of " +
                     std::to_string(model_.materials.size()));
    // Materials 0 .. n-1 are shaders 0 .. n-1, made on first use; the default one is n.
    const size_t count = model_.materials.size();
    if (shaderOf_.empty()) shaderOf_.assign(count + 1, -1);
    const size_t key = material < 0 ? count : size_t(material);
    if (shaderOf_[key] < 0) {
        if (scene_.shaders.size() >= size_t(kMaxShaders))
            fail(at, "more than " + std::to_string(kMaxShaders) + " materials");
        shaderOf_[key] = int(scene_.shaders.size());
        uvSetsRead_.clear();
        scene_.shaders.push_back(material < 0 ? defaultShader() : readMaterial(material));
        uvSetOf_[shaderOf_[key]] = material < 0 ? 0 : chooseUvSet(material);
    }
    return shaderOf_[key];
}

Shader GltfReader::readMaterial(int index) {
    const tinygltf::Material& file = model_.materials[size_t(index)];
    const std::string at = "/materials/" + std::to_string(index);
    const std::string name =
        "material " + std::to_string(index) + (file.name.empty() ? "" : " (" + file.name + ")");
    tinygltf::Material converted;
    std::optional<ConvertedImages> images;
    const tinygltf::Material& mat = readSpecularGlossiness(file, at, name, converted, images);
    Shader s = defaultShader();
    const tinygltf::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() != 4)
        fail(at + "/pbrMetallicRoughness/baseColorFactor", "needs 4 numbers");
    for (int k = 0; k < 3; ++k)
        s.params.colour[k] =
            unit(pbr.baseColorFactor[size_t(k)], at + "/pbrMetallicRoughness/baseColorFactor");
    s.params.metallic =
        float(unit(pbr.metallicFactor, at + "/pbrMetallicRoughness/metallicFactor"));
    s.roughness = float(unit(pbr.roughnessFactor, at + "/pbrMetallicRoughness/roughnessFactor"));
    s.params.alpha = gltfAlpha(s.roughness);
    readImages(mat, s, at, name, images ? &*images : nullptr);
    readTransmission(mat, s, at, name);
    readVolume(mat, s, at, name);
    readClearcoat(mat, s, at, name);
    readSheen(mat, s, at, name);
    readSpecular(mat, s, at, name);   // after the models that take the extension's images
    readPrincipled(mat, s, at, name); // replaces the three before it
    if (mat.alphaMode != "OPAQUE" && mat.alphaMode != "MASK" && mat.alphaMode != "BLEND")
        fail(at + "/alphaMode", "must be OPAQUE, MASK or BLEND");
    readEmission(mat, s, at, name);
    if (mat.doubleSided) s.params.flags |= kShaderTwoSided;
    return s;
}

void GltfReader::readImages(const tinygltf::Material& mat, Shader& s, const std::string& at,
                            const std::string& name, const ConvertedImages* converted) {
    const tinygltf::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
    std::optional<Texture> base, mr;
    if (converted) base = converted->base, mr = converted->metallicRoughness;
    if (pbr.baseColorTexture.index >= 0)
        base = imageTexture(pbr.baseColorTexture, at + "/pbrMetallicRoughness/baseColorTexture",
                            name + ": its baseColorTexture");
    if (pbr.metallicRoughnessTexture.index >= 0)
        mr = imageTexture(pbr.metallicRoughnessTexture,
                          at + "/pbrMetallicRoughness/metallicRoughnessTexture",
                          name + ": its metallicRoughnessTexture");
    if (base) baseColourTexture(*base, s);
    if (mat.alphaMode == "MASK" || mat.alphaMode == "BLEND")
        readCutout(mat, s, at, base ? &*base : nullptr);
    if (mr) {
        mr->linear = true;
        s.metallicRoughnessTexture = int(scene_.textures.size());
        scene_.textures.push_back(*mr);
        s.params.flags |= kShaderHitParams;
    }
    if (mat.normalTexture.index >= 0) {
        Texture normals =
            imageTexture(mat.normalTexture, at + "/normalTexture", name + ": its normalTexture");
        normals.linear = true;
        s.normalTexture = int(scene_.textures.size());
        scene_.textures.push_back(normals);
        s.normalScale = float(mat.normalTexture.scale);
        if (!std::isfinite(s.normalScale) || std::fabs(s.normalScale) > 1e3f)
            fail(at + "/normalTexture/scale", "must be a finite number of at most 1000");
    }
    if (mat.occlusionTexture.index >= 0)
        warnOf(name, "its occlusionTexture is ignored (a path tracer finds occlusion itself)");
}

void GltfReader::readEmission(const tinygltf::Material& mat, Shader& s, const std::string& at,
                              const std::string& name) {
    const auto e = mat.extensions.find("KHR_materials_emissive_strength");
    const double strength =
        e == mat.extensions.end()
            ? 1.0
            : extensionNumber(e->second, "emissiveStrength", 1.0, 0.0, HUGE_VAL,
                              at + "/extensions/KHR_materials_emissive_strength");
    if (mat.emissiveFactor.size() != 3) fail(at + "/emissiveFactor", "needs 3 numbers");
    for (int k = 0; k < 3; ++k) {
        const double e = unit(mat.emissiveFactor[size_t(k)], at + "/emissiveFactor") * strength;
        if (!(e <= kMaxRadiance))
            fail(at + "/extensions/KHR_materials_emissive_strength",
                 "emission beyond " + std::to_string(kMaxRadiance));
        s.params.emission[k] = float(e);
    }
    if (mat.emissiveTexture.index >= 0 && maxComponent(s.params.emission) > 0.0f) {
        s.emissionTexture = int(scene_.textures.size());
        scene_.textures.push_back(imageTexture(mat.emissiveTexture, at + "/emissiveTexture",
                                               name + ": its emissiveTexture"));
    }
}

void GltfReader::baseColourTexture(const Texture& picture, Shader& s) {
    Texture zero{};
    zero.colour = vec3(0.0f);
    Texture factor{};
    factor.colour = s.params.colour;
    const int base = int(scene_.textures.size());
    scene_.textures.push_back(picture);
    scene_.textures.push_back(zero);
    scene_.textures.push_back(factor);
    Texture layered{};
    layered.type = TextureType::Layered;
    layered.upper = base, layered.lower = base + 1, layered.mask = base + 2;
    scene_.textures.push_back(layered);
    s.texture = base + 3;
    s.params.flags |= kShaderTextured;
}

void GltfReader::readCutout(const tinygltf::Material& mat, Shader& s, const std::string& at,
                            const Texture* base) {
    const tinygltf::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
    Cutout& c = s.cutout;
    c.alpha = float(unit(pbr.baseColorFactor[3], at + "/pbrMetallicRoughness/baseColorFactor"));
    c.stochastic = mat.alphaMode == "BLEND";
    c.cutoff = float(mat.alphaCutoff);
    if (!(c.cutoff >= 0.0f) || !std::isfinite(mat.alphaCutoff))
        fail(at + "/alphaCutoff", "must be a non-negative number");
    if (base) {
        Texture alpha = *base;
        alpha.channel = 3;
        alpha.linear = true;
        c.texture = int(scene_.textures.size());
        scene_.textures.push_back(alpha);
    }
    // A factor that decides alone: MASK's at least the cutoff, or BLEND's 1, is no cut-out.
    c.enabled = c.texture >= 0 || (c.stochastic ? c.alpha < 1.0f : c.alpha < c.cutoff);
}

template <class Info>
Texture GltfReader::imageTexture(const Info& info, const std::string& where,
                                 const std::string& what) {
    const int index = info.index;
    if (info.texCoord < 0 || info.texCoord > kMaxUvSet)
        fail(where + "/texCoord", "must be an integer in [0, " + std::to_string(kMaxUvSet) + "]");
    if (index >= int(model_.textures.size()))
        fail(where, "names texture " + std::to_string(index) + " of " +
                        std::to_string(model_.textures.size()));
    const int source = model_.textures[size_t(index)].source;
    if (source < 0 || source >= int(model_.images.size()))
        fail("/textures/" + std::to_string(index) + "/source", "names no image");
    Texture picture{};
    const OpenedImage opened = openImage(source, picture);
    // Its size, from the header, before any pixel is read (a 400-byte PNG can claim 100000^2).
    const OIIO::ImageSpec& spec = opened.in->spec();
    if (const std::string why = imageSizeProblem(picture.path, spec.width, spec.height,
                                                 kMaxTexturePixels, kMaxTextureSide);
        !why.empty())
        fail("/images/" + std::to_string(source), why);
    const int transformSet = readTextureTransform(info, where, picture);
    uvSetsRead_.push_back(transformSet >= 0 ? transformSet : info.texCoord);
    if (const int sampler = model_.textures[size_t(index)].sampler; sampler >= 0) {
        if (sampler >= int(model_.samplers.size()))
            fail("/textures/" + std::to_string(index) + "/sampler",
                 "names sampler " + std::to_string(sampler) + " of " +
                     std::to_string(model_.samplers.size()));
        readSampler(model_.samplers[size_t(sampler)], "/samplers/" + std::to_string(sampler), what,
                    picture);
    }
    return picture;
}

GltfReader::OpenedImage GltfReader::openImage(int source, Texture& picture) const {
    const tinygltf::Image& image = model_.images[size_t(source)];
    picture.type = TextureType::Standard;
    const std::string imageAt = "/images/" + std::to_string(source);
    OpenedImage opened;
    // The colour as stored, never premultiplied by the alpha (as the texture cache reads it).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    std::unique_ptr<OIIO::Filesystem::IOProxy>& proxy = opened.proxy;
    std::unique_ptr<OIIO::ImageInput>& in = opened.in;
    if (const auto e = embedded_.find(source); e != embedded_.end()) {
        // A name no file has, its extension telling OpenImageIO the format its bytes are (not
        // the mimeType, which a file may get wrong).
        try {
            proxy = embeddedReader(*e->second);
        } catch (const std::runtime_error& x) {
            fail(imageAt, x.what());
        }
        char head[8] = {};
        const std::string ext = imageFormat(std::string(head, proxy->pread(head, 8, 0)));
        if (ext.empty()) fail(imageAt, "the embedded image is neither a PNG nor a JPEG");
        const auto read = [&](void* out, size_t n, std::uint64_t at) {
            return proxy->pread(out, n, std::int64_t(at));
        };
        if (const std::string why = jpegCutShort(read, proxy->size(), "the embedded image");
            !why.empty())
            fail(imageAt, why);
        picture.path = fs::absolute(path_).lexically_normal().string() + "#image" +
                       std::to_string(source) + ext;
        picture.embedded = e->second;
        void* reader = proxy.get(); // with a config, OpenImageIO takes the proxy from it
        config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &reader);
        in = OIIO::ImageInput::open(picture.path, &config, proxy.get());
        if (!in || in->spec().width < 1 || in->spec().height < 1)
            fail(imageAt, "the embedded image is not one OpenImageIO can read" + imageError());
    } else {
        if (image.uri.empty()) fail(imageAt, "an image needs a uri or a bufferView");
        picture.path = fs::absolute(dir_ / decodeGltfUri(image.uri)).lexically_normal().string();
        std::ifstream file(picture.path, std::ios::binary);
        char head[8] = {};
        file.read(head, 8);
        if (imageFormat(std::string(head, size_t(file.gcount()))).empty())
            fail(imageAt + "/uri", "'" + picture.path + "' is neither a PNG nor a JPEG image");
        if (const std::string why = jpegFileCutShort(picture.path); !why.empty())
            fail(imageAt + "/uri", why);
        in = OIIO::ImageInput::open(picture.path, &config);
        if (!in)
            fail(imageAt + "/uri",
                 "'" + picture.path + "' is not an image OpenImageIO can read" + imageError());
    }
    return opened;
}

tinygltf::TextureInfo GltfReader::extensionTextureInfo(const tinygltf::Value& ext, const char* key,
                                                       const std::string& at) const {
    const tinygltf::Value& v = ext.Get(key);
    if (!v.IsObject()) fail(at, "must be a textureInfo object");
    auto integer = [&](const char* field) {
        const tinygltf::Value& x = v.Get(field);
        const double d = x.IsNumber() ? x.GetNumberAsDouble() : NAN;
        if (!(d >= 0.0 && d <= double(std::numeric_limits<int>::max())) || d != std::floor(d))
            fail(at + "/" + field, "must be an integer of at least 0");
        return int(d);
    };
    if (!v.Has("index")) fail(at, "a textureInfo needs an index");
    tinygltf::TextureInfo info;
    info.index = integer("index");
    if (v.Has("texCoord")) info.texCoord = integer("texCoord");
    if (v.Has("extensions")) {
        const tinygltf::Value& e = v.Get("extensions");
        if (!e.IsObject()) fail(at + "/extensions", "must be an object");
        for (const std::string& name : e.Keys())
            info.extensions[name] = e.Get(name);
    }
    return info;
}

void GltfReader::checkUnusedTextures(const tinygltf::Value& ext,
                                     std::initializer_list<const char*> keys,
                                     const std::string& where) const {
    for (const char* key : keys) {
        if (!ext.Has(key)) continue;
        const std::string at = where + "/" + key;
        const int index = extensionTextureInfo(ext, key, at).index;
        if (index >= int(model_.textures.size()))
            fail(at, "names texture " + std::to_string(index) + " of " +
                         std::to_string(model_.textures.size()));
    }
}

int GltfReader::extensionTexture(const tinygltf::Value& ext, const char* key, int channel,
                                 bool colour, const std::string& where, const std::string& what) {
    if (!ext.Has(key)) return -1;
    const std::string at = where + "/" + key;
    Texture picture = imageTexture(extensionTextureInfo(ext, key, at), at, what);
    picture.channel = channel;
    picture.linear = !colour;
    scene_.textures.push_back(picture);
    return int(scene_.textures.size()) - 1;
}

std::string GltfReader::imageError() {
    std::string why = OIIO::geterror();
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r'))
        why.pop_back();
    return why.empty() ? "" : ": " + why;
}

void GltfReader::readSampler(const tinygltf::Sampler& s, const std::string& at,
                             const std::string& what, Texture& picture) {
    auto wrap = [&](int mode, const char* field) {
        switch (mode) {
        case TINYGLTF_TEXTURE_WRAP_REPEAT:
            return Texture::Wrap::Repeat;
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
            return Texture::Wrap::Clamp;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
            return Texture::Wrap::Mirror;
        default:
            fail(at + "/" + field, "must be 33071, 33648 or 10497");
        }
    };
    picture.wrapU = wrap(s.wrapS, "wrapS");
    picture.wrapV = wrap(s.wrapT, "wrapT");
    if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
        s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
        s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
        s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR)
        warn(what + "'s sampler asks for NEAREST filtering: rendered bilinear");
}

template <class Info>
int GltfReader::readTextureTransform(const Info& info, const std::string& where, Texture& picture) {
    const auto e = info.extensions.find("KHR_texture_transform");
    if (e == info.extensions.end()) return -1;
    const std::string at = where + "/extensions/KHR_texture_transform";
    auto numbers = [&](const char* key, std::vector<double> fallback) {
        if (!e->second.Has(key)) return fallback;
        const tinygltf::Value& v = e->second.Get(key);
        std::vector<double> out;
        if (v.IsNumber()) out.push_back(v.GetNumberAsDouble());
        for (int i = 0; v.IsArray() && i < int(v.ArrayLen()); ++i)
            out.push_back(v.Get(i).IsNumber() ? v.Get(i).GetNumberAsDouble() : NAN);
        for (double x : out)
            if (!std::isfinite(x) || std::fabs(x) > 1e6)
                fail(at + "/" + key, "must be finite numbers of at most 1e6");
        if (out.size() != fallback.size())
            fail(at + "/" + key, "needs " + std::to_string(fallback.size()) + " numbers");
        return out;
    };
    const std::vector<double> offset = numbers("offset", {0.0, 0.0});
    const double rotation = numbers("rotation", {0.0})[0];
    const std::vector<double> scale = numbers("scale", {1.0, 1.0});
    int set = -1;
    if (e->second.Has("texCoord")) {
        const tinygltf::Value& v = e->second.Get("texCoord");
        const double n = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
        if (!(n >= 0.0 && n <= kMaxUvSet) || n != std::floor(n))
            fail(at + "/texCoord", "must be an integer in [0, " + std::to_string(kMaxUvSet) + "]");
        set = int(n);
    }
    const double c = std::cos(rotation), sn = std::sin(rotation);
    // Column by column. The rotation is (u, v) -> (c u + s v, -s u + c v) in glTF's V-down
    // coordinates: the extension's sample GLSL writes the transpose (it was written for V-up),
    // but its reference model (TextureTransformTest), Blender's importer, three.js and
    // Babylon.js all turn this way, the image clockwise as it is seen upright.
    const glm::dmat3 t(1, 0, 0, 0, 1, 0, offset[0], offset[1], 1);
    const glm::dmat3 r(c, -sn, 0, sn, c, 0, 0, 0, 1);
    const glm::dmat3 sc(scale[0], 0, 0, 0, scale[1], 0, 0, 0, 1);
    const glm::dmat3 flip(1, 0, 0, 0, -1, 0, 0, 1, 1); // (u, v) -> (u, 1 - v)
    picture.uvTransformed = true;
    picture.uvTransform = mat3(flip * t * r * sc * flip);
    picture.footprintScale = float(std::max({std::fabs(scale[0]), std::fabs(scale[1]), 1e-6}));
    return set;
}

int GltfReader::chooseUvSet(int material) {
    if (uvSetsRead_.empty()) return 0;
    const int chosen = uvSetsRead_.front();
    for (int set : uvSetsRead_)
        if (set != chosen) {
            warn("material " + std::to_string(material) + "'s images name TEXCOORD_" +
                 std::to_string(chosen) + " and TEXCOORD_" + std::to_string(set) +
                 ": all are read through TEXCOORD_" + std::to_string(chosen) +
                 ", the first one's (a mesh carries one set)");
            break;
        }
    return chosen;
}

// Used by gltf_specular_glossiness.cpp too.
template Texture GltfReader::imageTexture(const tinygltf::TextureInfo&, const std::string&,
                                          const std::string&);

} // namespace spw
