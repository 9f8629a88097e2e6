// Spheres for the glTF material tests: a UV sphere of radius 1 in glTF's white furnace (a uniform
// environment of radiance 1, its default without lights) seen by a camera it fills most of, and
// the materials of the extensions (KHR_materials_transmission, _ior, _volume, _clearcoat,
// _specular, _sheen) the tests put on it.
#pragma once

#include "scene/gltf_builder.h"
#include "test_util.h"

#include <cmath>
#include <string>
#include <vector>

namespace spw::test {

// A UV sphere of radius 1 (48 around, 24 rings) with its normals, material 0.
inline json sphere(GltfBuilder& b, bool uvs = false) {
    std::vector<float> pos;
    std::vector<uint32_t> idx;
    const int rings = 24, segments = 48;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s <= segments; ++s) {
            const double t = M_PI * r / rings, p = 2.0 * M_PI * s / segments;
            pos.insert(pos.end(), {float(std::sin(t) * std::cos(p)), float(std::cos(t)),
                                   float(-std::sin(t) * std::sin(p))});
        }
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const uint32_t a = uint32_t(r * (segments + 1) + s), c = a + uint32_t(segments) + 1;
            idx.insert(idx.end(), {a, c, a + 1, a + 1, c, c + 1});
        }
    json prim = {{"attributes",
                  {{"POSITION", b.accessor<float>(pos, 5126, "VEC3")},
                   {"NORMAL", b.accessor<float>(pos, 5126, "VEC3")}}},
                 {"indices", b.accessor<uint32_t>(idx, 5125, "SCALAR")},
                 {"material", 0}};
    if (uvs) {
        std::vector<float> uv;
        for (int r = 0; r <= rings; ++r)
            for (int s = 0; s <= segments; ++s)
                uv.insert(uv.end(), {float(s) / segments, float(r) / rings});
        prim["attributes"]["TEXCOORD_0"] = b.accessor<float>(uv, 5126, "VEC2");
    }
    return prim;
}

// The sphere of material `mat`, filling most of the view, no light: glTF's uniform environment.
// `images`: files in `dir` that textures 0, 1, ... show, the sphere taking texture coordinates
// where there are any.
inline std::string sphereFile(const TempDir& dir, const json& mat,
                              const std::vector<std::string>& images = {}) {
    GltfBuilder b;
    b.doc["materials"] = json::array({mat});
    for (size_t k = 0; k < images.size(); ++k) {
        b.doc["images"].push_back({{"uri", images[k]}});
        b.doc["textures"].push_back({{"source", k}});
    }
    b.doc["extensionsUsed"] = {"KHR_materials_transmission",   "KHR_materials_ior",
                               "KHR_materials_volume",         "KHR_materials_clearcoat",
                               "KHR_materials_specular",       "KHR_materials_sheen",
                               "SPILLWAY_materials_principled"};
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.6}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene({b.node({{"mesh", b.mesh(sphere(b, !images.empty()))}}),
             b.node({{"camera", 0}, {"translation", {0, 0, 3.5}}})});
    return b.embedded(dir, "glass.gltf");
}

inline json glass(double transmission, double ior, double roughness = 0.0) {
    json m = material(vec3(1.0f), 0.0f, float(roughness));
    m["extensions"]["KHR_materials_transmission"]["transmissionFactor"] = transmission;
    m["extensions"]["KHR_materials_ior"]["ior"] = ior;
    return m;
}

// glass with KHR_materials_volume's attenuation: `colour` left after `distance`, thickness 1.
inline json volume(json m, std::vector<double> colour, double distance) {
    m["extensions"]["KHR_materials_volume"] = {
        {"thicknessFactor", 1.0}, {"attenuationColor", colour}, {"attenuationDistance", distance}};
    return m;
}

// A black smooth dielectric under a smooth clear coat of weight `coat` and roughness `roughness`.
inline json coated(double coat, double roughness) {
    json m = material(vec3(0.0f), 0.0f, 0.0f);
    m["extensions"]["KHR_materials_clearcoat"] = {{"clearcoatFactor", coat},
                                                  {"clearcoatRoughnessFactor", roughness}};
    return m;
}

// A black smooth dielectric with KHR_materials_specular's weight and F0 colour.
inline json specular(double weight, std::vector<double> colour) {
    json m = material(vec3(0.0f), 0.0f, 0.0f);
    m["extensions"]["KHR_materials_specular"] = {{"specularFactor", weight},
                                                 {"specularColorFactor", colour}};
    return m;
}

// A black dielectric whose reflection is off (KHR_materials_specular's weight 0) under a sheen.
inline json sheen(std::vector<double> colour, double roughness) {
    json m = specular(0.0, {1.0, 1.0, 1.0});
    m["extensions"]["KHR_materials_sheen"] = {{"sheenColorFactor", colour},
                                              {"sheenRoughnessFactor", roughness}};
    return m;
}

} // namespace spw::test
