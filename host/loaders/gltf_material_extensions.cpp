// GltfReader's material extensions (gltf_reader.h): KHR_materials_transmission with _ior and
// _volume, _clearcoat, _specular and _sheen, each a part of the metallic-roughness model or a
// surface model of its own, their factors and images (the images as Shader::extension's maps).
#include "host/loaders/gltf_reader.h"

#include "shared/metallic_roughness.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace spw {

namespace {
// x as the shortest decimal that reads back as it (1.01, not 1.010000).
std::string number(double x) {
    std::ostringstream out;
    out << x;
    return out.str();
}

} // namespace

double GltfReader::extensionNumber(const tinygltf::Value& ext, const char* key, double fallback,
                                   double lo, double hi, const std::string& at) const {
    if (!ext.Has(key)) return fallback;
    const tinygltf::Value& v = ext.Get(key);
    const double x = v.IsNumber() ? v.GetNumberAsDouble() : NAN;
    if (!(x >= lo && x <= hi) || !std::isfinite(x))
        fail(at + "/" + key, std::isfinite(hi)
                                 ? "must be a number in [" + number(lo) + ", " + number(hi) + "]"
                                 : "must be a finite number of at least " + number(lo));
    return x;
}

vec3 GltfReader::extensionColour(const tinygltf::Value& ext, const char* key, vec3 fallback,
                                 double hi, const std::string& at) const {
    if (!ext.Has(key)) return fallback;
    const tinygltf::Value& values = ext.Get(key);
    const std::string where = at + "/" + key;
    const std::string range = std::isfinite(hi) ? "in [0, " + number(hi) + "]" : "of at least 0";
    if (!values.IsArray() || values.ArrayLen() != 3) fail(where, "needs 3 numbers " + range);
    vec3 colour;
    for (int k = 0; k < 3; ++k) {
        const tinygltf::Value& v = values.Get(k);
        const double x = v.IsNumber() ? v.GetNumberAsDouble() : NAN;
        if (!(x >= 0.0 && x <= hi) || !std::isfinite(x))
            fail(where + "/" + std::to_string(k),
                 std::isfinite(hi) ? "must be a number in [0, " + number(hi) + "]"
                                   : "must be a finite number of at least 0");
        colour[k] = float(std::min(x, 1e3));
    }
    return colour;
}

void GltfReader::readTransmission(const tinygltf::Material& mat, Shader& s, const std::string& at,
                                  const std::string& name) {
    const auto iorExt = mat.extensions.find("KHR_materials_ior");
    double ior = 1.5;
    if (iorExt != mat.extensions.end()) {
        ior = extensionNumber(iorExt->second, "ior", 1.5, 0.0, 10.0,
                              at + "/extensions/KHR_materials_ior");
        if (ior > 0.0 && ior < 1.0)
            fail(at + "/extensions/KHR_materials_ior/ior", "must be 0 or at least 1");
    }
    const auto t = mat.extensions.find("KHR_materials_transmission");
    const double factor = t == mat.extensions.end()
                              ? 0.0
                              : extensionNumber(t->second, "transmissionFactor", 0.0, 0.0, 1.0,
                                                at + "/extensions/KHR_materials_transmission");
    const bool textured = t != mat.extensions.end() && t->second.Has("transmissionTexture");
    // Opaque, the ior sets the dielectric reflection's F0 ((ior - 1) / (ior + 1))^2
    // (shared/metallic_roughness.h's gltfDielectricF0); 0 keeps glTF's 0.04.
    if (ior == 0.0 && iorExt != mat.extensions.end())
        warnOf(name, "KHR_materials_ior's ior 0 is rendered as 1.5");
    s.params.ior = float(ior == 0.0 ? 1.5 : ior);
    if (factor == 0.0) {
        if (t != mat.extensions.end())
            checkUnusedTextures(t->second, {"transmissionTexture"},
                                at + "/extensions/KHR_materials_transmission");
        return;
    }
    if (ior > 0.0 && ior < kMinGlassIor)
        warnOf(name,
               "an ior below " + number(kMinGlassIor) + " is rendered as " + number(kMinGlassIor));
    // Below 1, where an image may make it so, or on a metal, glass mixed with the opaque material
    // (shared/transmissive_metallic_roughness.h); the image's red channel times the factor at each
    // hit.
    const bool metal = s.params.metallic > 0.0f || s.metallicRoughnessTexture >= 0;
    const bool partial = factor < 1.0 || textured || metal;
    s.typeName = partial ? "TransmissiveMetallicRoughness" : "Dielectric";
    s.params.model = partial ? kModelTransmissiveMetallicRoughness : kModelDielectric;
    s.params.transmission = float(factor);
    if (textured) {
        s.extension[0] = {extensionTexture(t->second, "transmissionTexture", 0, false,
                                           at + "/extensions/KHR_materials_transmission",
                                           name + ": its transmissionTexture"),
                          0, float(factor)};
        s.params.flags |= kShaderHitExtension;
    }
    s.params.ior = float(ior == 0.0 ? 1.5 : std::max(ior, kMinGlassIor));
    s.params.alpha = s.roughness * s.roughness; // below kGgxSmoothAlpha: smooth glass
    // The base colour (its factor, image and vertex colours) tints what the glass refracts. A
    // metallic-roughness image gives each hit its metallic and (floored as MetallicRoughness
    // floors it) roughness, for the glass too.
}

void GltfReader::readVolume(const tinygltf::Material& mat, Shader& s, const std::string& at,
                            const std::string& name) {
    const auto v = mat.extensions.find("KHR_materials_volume");
    if (v == mat.extensions.end()) return;
    const std::string where = at + "/extensions/KHR_materials_volume";
    const double thickness =
        extensionNumber(v->second, "thicknessFactor", 0.0, 0.0, HUGE_VAL, where);
    const double distance =
        extensionNumber(v->second, "attenuationDistance", HUGE_VAL, 0.0, HUGE_VAL, where);
    if (v->second.Has("attenuationDistance") && !(distance > 0.0))
        fail(where + "/attenuationDistance", "must be a positive number");
    const vec3 colour = extensionColour(v->second, "attenuationColor", vec3(1.0f), 1.0, where);
    if (v->second.Has("thicknessTexture"))
        warnOf(name, "its thicknessTexture is not read (the mesh's own thickness is rendered)");
    const bool transmits =
        s.params.model == kModelDielectric || s.params.model == kModelTransmissiveMetallicRoughness;
    if (!transmits || !std::isfinite(distance) || colour == vec3(1.0f))
        return; // nothing absorbs: the volume of an opaque material is never entered
    if (thickness == 0.0) {
        warnOf(name, "KHR_materials_volume's thicknessFactor 0 makes it thin-walled: its "
                     "attenuation is not rendered");
        return;
    }
    // Beer-Lambert: attenuationColor is what is left after attenuationDistance.
    for (int k = 0; k < 3; ++k)
        s.params.absorption[k] = float(-std::log(std::max(double(colour[k]), 1e-30)) / distance);
    if (!std::isfinite(maxComponent(s.params.absorption)))
        fail(where + "/attenuationDistance", "gives an absorption beyond the float range");
}

void GltfReader::readClearcoat(const tinygltf::Material& mat, Shader& s, const std::string& at,
                               const std::string& name) {
    const auto c = mat.extensions.find("KHR_materials_clearcoat");
    if (c == mat.extensions.end()) return;
    const std::string where = at + "/extensions/KHR_materials_clearcoat";
    const double factor = extensionNumber(c->second, "clearcoatFactor", 0.0, 0.0, 1.0, where);
    const double roughness =
        extensionNumber(c->second, "clearcoatRoughnessFactor", 0.0, 0.0, 1.0, where);
    if (factor == 0.0 || s.params.model != kModelMetallicRoughness) {
        if (factor != 0.0) warnOf(name, "a clear coat on glass is not rendered");
        checkUnusedTextures(
            c->second, {"clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture"},
            where);
        return;
    }
    s.typeName = "CoatedMetallicRoughness";
    s.params.model = kModelCoatedMetallicRoughness;
    s.params.coat = float(factor);
    s.params.coatAlpha = gltfAlpha(float(roughness));
    // The weight times the red channel of clearcoatTexture, the roughness times the green of
    // clearcoatRoughnessTexture.
    const int weight = extensionTexture(c->second, "clearcoatTexture", 0, false, where,
                                        name + ": its clearcoatTexture");
    const int rough = extensionTexture(c->second, "clearcoatRoughnessTexture", 0, false, where,
                                       name + ": its clearcoatRoughnessTexture");
    s.extension[0] = {weight, 0, float(factor)};
    s.extension[1] = {rough, 1, float(roughness)};
    if (weight >= 0 || rough >= 0) s.params.flags |= kShaderHitExtension;
    // The coat's own normal map; without one the coat is not normal-mapped, even where the base
    // is: it takes the interpolated normal.
    s.coatNormalTexture = extensionTexture(c->second, "clearcoatNormalTexture", 0, false, where,
                                           name + ": its clearcoatNormalTexture");
    if (s.coatNormalTexture >= 0)
        s.coatNormalScale =
            float(extensionNumber(c->second.Get("clearcoatNormalTexture"), "scale", 1.0, -1e3, 1e3,
                                  where + "/clearcoatNormalTexture"));
    if (s.coatNormalTexture >= 0 || s.normalTexture >= 0)
        s.params.flags |= kShaderHitExtension | kShaderCoatNormal;
}

void GltfReader::readSpecular(const tinygltf::Material& mat, Shader& s, const std::string& at,
                              const std::string& name) {
    const auto e = mat.extensions.find("KHR_materials_specular");
    if (e == mat.extensions.end()) return;
    const std::string where = at + "/extensions/KHR_materials_specular";
    const double factor = extensionNumber(e->second, "specularFactor", 1.0, 0.0, 1.0, where);
    // Unbounded above by the specification; taken up to 1000.
    const vec3 colour =
        extensionColour(e->second, "specularColorFactor", vec3(1.0f), HUGE_VAL, where);
    const bool textured = e->second.Has("specularTexture") || e->second.Has("specularColorTexture");
    if (factor == 1.0 && colour == vec3(1.0f) && !textured)
        return; // the defaults: glTF's own reflection
    const auto images = {"specularTexture", "specularColorTexture"};
    if (s.params.model == kModelDielectric ||
        s.params.model == kModelTransmissiveMetallicRoughness) {
        warnOf(name, "KHR_materials_specular on glass is not rendered (its reflection follows "
                     "the ior alone)");
        checkUnusedTextures(e->second, images, where);
        return;
    }
    s.params.flags |= kShaderSpecular;
    s.params.specular = float(factor);
    s.params.specularColour = colour;
    if (!textured) return;
    if (s.params.model != kModelMetallicRoughness) {
        warnOf(name, "KHR_materials_specular's images are not rendered on a clear coat or a "
                     "sheen (its factors are)");
        checkUnusedTextures(e->second, images, where);
        return;
    }
    // The colour times specularColorTexture's RGB (sRGB), the weight times specularTexture's
    // alpha.
    const int tint = extensionTexture(e->second, "specularColorTexture", 0, true, where,
                                      name + ": its specularColorTexture");
    const int weight = extensionTexture(e->second, "specularTexture", 3, false, where,
                                        name + ": its specularTexture");
    for (int k = 0; k < 3; ++k)
        s.extension[size_t(k)] = {tint, k, colour[k]};
    s.extension[3] = {weight, 0, float(factor)};
    s.params.flags |= kShaderHitExtension;
}

void GltfReader::readSheen(const tinygltf::Material& mat, Shader& s, const std::string& at,
                           const std::string& name) {
    const auto e = mat.extensions.find("KHR_materials_sheen");
    if (e == mat.extensions.end()) return;
    const std::string where = at + "/extensions/KHR_materials_sheen";
    const vec3 colour = extensionColour(e->second, "sheenColorFactor", vec3(0.0f), 1.0, where);
    const double roughness =
        extensionNumber(e->second, "sheenRoughnessFactor", 0.0, 0.0, 1.0, where);
    if (colour == vec3(0.0f) || s.params.model != kModelMetallicRoughness) {
        if (colour != vec3(0.0f))
            warnOf(name, std::string("a sheen on ") +
                             (s.params.model == kModelCoatedMetallicRoughness ? "a clear coat"
                                                                              : "glass") +
                             " is not rendered");
        checkUnusedTextures(e->second, {"sheenColorTexture", "sheenRoughnessTexture"}, where);
        return;
    }
    s.typeName = "SheenMetallicRoughness";
    s.params.model = kModelSheenMetallicRoughness;
    s.params.sheenColour = colour;
    s.params.sheenRoughness = float(roughness);
    // The colour times sheenColorTexture's RGB (sRGB), the roughness times
    // sheenRoughnessTexture's alpha.
    const int tint = extensionTexture(e->second, "sheenColorTexture", 0, true, where,
                                      name + ": its sheenColorTexture");
    const int rough = extensionTexture(e->second, "sheenRoughnessTexture", 3, false, where,
                                       name + ": its sheenRoughnessTexture");
    for (int k = 0; k < 3; ++k)
        s.extension[size_t(k)] = {tint, k, colour[k]};
    s.extension[3] = {rough, 0, float(roughness)};
    if (tint >= 0 || rough >= 0) s.params.flags |= kShaderHitExtension;
}

void GltfReader::readPrincipled(const tinygltf::Material& mat, Shader& s, const std::string& at,
                                const std::string& name) {
    const auto e = mat.extensions.find(kPrincipledExtension);
    if (e == mat.extensions.end()) return;
    const std::string where = at + "/extensions/" + kPrincipledExtension;
    const tinygltf::Value& v = e->second;
    const auto factor = [&](const char* key, double fallback) {
        return float(extensionNumber(v, key, fallback, 0.0, 1.0, where));
    };
    const float specular = factor("specular", 0.5), specularTint = factor("specularTint", 0.0),
                sheen = factor("sheen", 0.0), sheenTint = factor("sheenTint", 0.5),
                coat = factor("clearcoat", 0.0), coatRoughness = factor("clearcoatRoughness", 0.03);
    if (s.params.model == kModelDielectric ||
        s.params.model == kModelTransmissiveMetallicRoughness) {
        warnOf(name, std::string(kPrincipledExtension) +
                         " on glass is not rendered (the glass is KHR_materials_transmission's)");
        return;
    }
    if ((s.params.flags & kShaderHitExtension) != 0u || s.coatNormalTexture >= 0)
        warnOf(name, "the images of its clear coat, sheen or specular extensions are not rendered "
                     "under " +
                         std::string(kPrincipledExtension) + " (its factors are)");
    s.typeName = "Principled";
    s.params.model = kModelPrincipled;
    s.params.flags &= ~(kShaderSpecular | kShaderHitExtension | kShaderCoatNormal);
    s.extension = {};
    s.coatNormalTexture = -1;
    s.params.specular = specular;
    s.params.specularColour = vec3(1.0f);
    s.params.specularTint = specularTint;
    s.params.sheen = sheen;
    s.params.sheenTint = sheenTint;
    s.params.coat = coat;
    s.params.coatAlpha = gltfAlpha(coatRoughness);
}

} // namespace spw
