// glTF 2.0 files (host/loaders/gltf_loader.h), written by the tests: `.gltf` with embedded and
// external buffers and `.glb`; every index and accessor component type, strides, normalized
// texture coordinates; node hierarchies of matrices and TRS; cameras, lights, emissive
// materials and what is not rendered (warnings, once); malformed files, each a SceneError
// naming the file and where in it; and rendering on every backend.
#include "host/image/image_io.h"
#include "host/loaders/gltf_loader.h"
#include "host/loaders/scene_loader.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include "shared/metallic_roughness.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <fstream>
#include <functional>

namespace spw::test {
namespace {

using nlohmann::json;

// A quad 4 units in front of a camera at (0, 0, 5) looking down -Z, scaled 2x by its parent,
// its child moved by a matrix; a second material on the child.
GltfBuilder cameraAndQuads() {
    GltfBuilder b;
    b.doc["materials"] = json::array(
        {material(vec3(0.8f, 0.5f, 0.25f), 0.25f, 0.5f), material(vec3(1.0f), 1.0f, 0.0f)});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.8}, {"aspectRatio", 2.0}, {"znear", 0.1}}}}});
    const int quadA = b.mesh(b.quad(0, 5121));
    const int quadB = b.mesh(b.quad(1, 5125));
    const int child =
        b.node({{"mesh", quadB}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 3, 0, 0, 1}}});
    const int parent = b.node(
        {{"mesh", quadA}, {"scale", {2, 2, 2}}, {"translation", {0, 0, 1}}, {"children", {child}}});
    const int camera = b.node({{"camera", 0}, {"translation", {0, 0, 5}}});
    b.scene({parent, camera});
    return b;
}

TEST(Gltf, MeshesTransformsCameraAndMaterialsLoad) {
    TempDir dir;
    GltfBuilder b = cameraAndQuads();
    const Scene s = loadScene(b.embedded(dir, "quads.gltf"));
    EXPECT_EQ(s.origin, glm::dvec3(0, 0, 5));
    ASSERT_TRUE(s.camera.fovDegrees);
    EXPECT_NEAR(std::tan(glm::radians(*s.camera.fovDegrees) / 2), std::tan(0.4) * 2.0, 1e-5);
    EXPECT_EQ(s.image.width, 640);
    EXPECT_EQ(s.image.height, 320);
    ASSERT_EQ(s.meshes.size(), 2u);
    ASSERT_EQ(s.objectCount, 2);
    // Parent: scale 2, then up 1 in z; camera-relative: z - 5.
    EXPECT_EQ(s.meshes[0].positions[2], vec3(2, 2, -4));
    // Child: its matrix moves it 3 along x, inside the parent's scale: x = 2 (1 + 3).
    EXPECT_EQ(s.meshes[1].positions[1], vec3(8, 0, -4));
    EXPECT_EQ(s.meshes[0].normals[0], vec3(0, 0, 1));
    EXPECT_EQ(s.meshes[0].uvs[0], vec2(0, 0)); // glTF's v = 1 is the image's bottom
    EXPECT_EQ(s.meshes[0].triangles.size(), 2u);
    ASSERT_EQ(s.shaders.size(), 2u);
    const ShaderParams& a = s.shaders[size_t(s.meshes[0].shader)].params;
    EXPECT_EQ(a.model, kModelMetallicRoughness);
    EXPECT_EQ(a.colour, vec3(0.8f, 0.5f, 0.25f));
    EXPECT_EQ(a.metallic, 0.25f);
    EXPECT_EQ(a.alpha, 0.25f);
    EXPECT_EQ(s.shaders[size_t(s.meshes[1].shader)].params.alpha, kGltfMinAlpha);
    // No light and no emission: a uniform environment of radiance 1.
    ASSERT_TRUE(s.environment);
    EXPECT_EQ(s.environment->radiance, vec3(1.0f));
    EXPECT_TRUE(s.warnings.empty());
}

// The same document embedded, beside an external buffer and as a .glb: the same scene.
TEST(Gltf, EmbeddedExternalAndBinaryFilesAreTheSameScene) {
    TempDir dir;
    GltfBuilder b = cameraAndQuads();
    const Scene e = loadScene(b.embedded(dir, "a.gltf"));
    for (const std::string& path : {b.external(dir, "b.gltf"), b.binary(dir, "c.glb")}) {
        const Scene s = loadScene(path);
        ASSERT_EQ(s.meshes.size(), e.meshes.size()) << path;
        for (size_t m = 0; m < s.meshes.size(); ++m) {
            EXPECT_EQ(s.meshes[m].positions, e.meshes[m].positions) << path;
            EXPECT_EQ(s.meshes[m].triangles, e.meshes[m].triangles) << path;
        }
    }
}

// Every index type, and texture coordinates as normalized integers in an interleaved view.
TEST(Gltf, EveryIndexAndComponentTypeReads) {
    TempDir dir;
    for (int indexType : {5121, 5123, 5125})
        for (int uvType : {5126, 5121, 5123}) {
            GltfBuilder b;
            json prim = b.quad(-1, indexType);
            if (uvType == 5121)
                prim["attributes"]["TEXCOORD_0"] =
                    b.accessor<uint8_t>({0, 255, 255, 255, 255, 0, 0, 0}, 5121, "VEC2", true, 4);
            if (uvType == 5123)
                prim["attributes"]["TEXCOORD_0"] = b.accessor<uint16_t>(
                    {0, 65535, 65535, 65535, 65535, 0, 0, 0}, 5123, "VEC2", true, 8);
            b.scene({b.node({{"mesh", b.mesh(prim)}})});
            const Scene s = loadScene(b.embedded(dir, "t.gltf"));
            ASSERT_EQ(s.meshes.size(), 1u);
            EXPECT_EQ(s.meshes[0].triangles[1], uvec3(0, 2, 3)) << indexType;
            EXPECT_EQ(s.meshes[0].uvs[1], vec2(1, 0)) << uvType;
            EXPECT_EQ(s.meshes[0].uvs[2], vec2(1, 1)) << uvType;
        }
}

TEST(Gltf, LightsEmissionAndWhatIsNotRenderedIsWarnedOnce) {
    TempDir dir;
    GltfBuilder b;
    json emissive = material(vec3(0.5f), 0.0f, 1.0f, vec3(1.0f, 0.5f, 0.25f));
    emissive["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = 4.0;
    b.doc["materials"] = json::array({emissive});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                               "EXT_unknown"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({{{"type", "point"}, {"intensity", 683.0}, {"color", {1.0, 0.5, 0.0}}},
                     {{"type", "directional"}, {"intensity", 1366.0}},
                     {{"type", "spot"},
                      {"intensity", 683.0},
                      {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}}});
    json prim = b.quad(0);
    prim["attributes"]["TANGENT"] = prim["attributes"]["NORMAL"]; // read as nothing: warned
    const int mesh = b.mesh(prim);
    b.scene({b.node({{"mesh", mesh}}), b.node({{"mesh", mesh}, {"translation", {0, 0, -2}}}),
             b.node({{"translation", {1, 2, 3}},
                     {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}),
             b.node({{"rotation", {-0.7071068, 0, 0, 0.7071068}},
                     {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}}),
             b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}})});
    b.doc["animations"] = json::array({{{"channels", json::array()}, {"samplers", json::array()}}});
    const Scene s = loadScene(b.embedded(dir, "lit.gltf"));
    EXPECT_EQ(s.shaders[0].params.emission, vec3(4.0f, 2.0f, 1.0f));
    ASSERT_EQ(s.punctualLights.size(), 3u);
    EXPECT_EQ(s.punctualLights[0].kind, kEmitterPoint);
    EXPECT_EQ(s.punctualLights[0].intensity, vec3(1.0f, 0.5f, 0.0f)); // 683 cd: 1 W/sr
    EXPECT_EQ(s.punctualLights[1].kind, kEmitterDirectional);
    EXPECT_NEAR(s.punctualLights[1].direction.y, -1.0f, 1e-6f); // -Z turned down
    EXPECT_EQ(s.punctualLights[1].intensity, vec3(2.0f));
    EXPECT_EQ(s.punctualLights[2].kind, kEmitterSpot);
    EXPECT_EQ(s.punctualLights[2].direction, vec3(0, 0, -1));
    EXPECT_EQ(s.punctualLights[2].cosInner, float(std::cos(0.25)));
    EXPECT_EQ(s.punctualLights[2].cosOuter, float(std::cos(0.5)));
    EXPECT_FALSE(s.environment); // lit by its lights
    std::string all;
    for (const std::string& w : s.warnings)
        all += w + "\n";
    for (const char* what : {"EXT_unknown", "animations", "TANGENT"})
        EXPECT_NE(all.find(what), std::string::npos) << what << " not in:\n" << all;
    EXPECT_EQ(s.warnings.size(), 3u) << all; // the two meshes' tangents warned once
}

// Each malformed file: a SceneError naming the file and, where it helps, the JSON pointer.
TEST(Gltf, MalformedFilesAreErrorsNamingTheFileAndWhere) {
    TempDir dir;
    auto expectError = [&](const std::string& path, const std::string& part) {
        try {
            loadScene(path);
            ADD_FAILURE() << path << ": loaded";
        } catch (const SceneError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
            EXPECT_NE(what.find(part), std::string::npos) << what;
        }
    };
    expectError(dir.write("bad.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": ["),
                "not a glTF 2.0 file");
    {
        GltfBuilder b;
        json prim = b.quad();
        b.doc["accessors"][size_t(prim["indices"])]["count"] = 600;
        b.scene({b.node({{"mesh", b.mesh(prim)}})});
        expectError(b.embedded(dir, "range.gltf"), "past the end");
    }
    {
        GltfBuilder b;
        json prim = b.quad();
        prim["indices"] = b.accessor<uint16_t>({0, 1, 7}, 5123, "SCALAR");
        b.scene({b.node({{"mesh", b.mesh(prim)}})});
        expectError(b.embedded(dir, "index.gltf"), "index 7 is past the vertex count 4");
    }
    {
        GltfBuilder b;
        const int mesh = b.mesh(b.quad());
        b.node({{"mesh", mesh}, {"children", {1}}});
        b.node({{"children", {0}}});
        b.scene({0});
        // A cycle through a scene's root: the root has a parent (gltf_preflight.cpp's forest).
        expectError(b.embedded(dir, "loop.gltf"), "names node 0, a child of node 1");
    }
    {
        GltfBuilder b;
        const float nan = std::numeric_limits<float>::quiet_NaN();
        json prim = b.quad();
        prim["attributes"]["POSITION"] = b.accessor<float>(
            {0, 0, 0, 1, 0, 0, 1, nan, 0, 0, std::numeric_limits<float>::infinity(), 0}, 5126,
            "VEC3");
        b.doc["accessors"].back()["min"] = {0, 0, 0};
        b.doc["accessors"].back()["max"] = {1, 1, 0};
        b.scene({b.node({{"mesh", b.mesh(prim)}})});
        expectError(b.embedded(dir, "nan.gltf"), "is not finite");
    }
    {
        GltfBuilder b;
        b.scene({b.node({{"mesh", b.mesh(b.quad())}})});
        const std::string path = b.external(dir, "missing.gltf");
        std::filesystem::remove(path + ".bin");
        expectError(path, "missing.gltf.bin");
    }
    {
        GltfBuilder b;
        b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
        b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
        b.scene({b.node({{"mesh", b.mesh(b.quad())}})});
        expectError(b.embedded(dir, "draco.gltf"), "/extensionsRequired");
    }
}

// `spillway render model.glb` on every backend: an image, the same on the cpu and reference
// backends to the bit (full-precision rays), and bad files exit 2 leaving nothing behind.
TEST(Gltf, EveryBackendRendersAFileDirectly) {
    TempDir dir;
    GltfBuilder b = cameraAndQuads();
    const std::string glb = b.binary(dir, "model.glb");
    for (const std::string& backend : backendsUnderTest()) {
        const std::string out = dir.file(backend + ".exr");
        const CommandResult r =
            runSpillway("render " + glb + " --backend " + backend +
                        " --spp 4 --width 32 --height 16 -o " + out + " --quiet");
        EXPECT_EQ(r.status, 0) << backend << ": " << r.output;
        EXPECT_TRUE(std::filesystem::exists(out)) << backend;
    }
    const std::string bad = dir.write("bad.glb", "glTF nonsense");
    const CommandResult r = runSpillway("render " + bad + " -o " + dir.file("bad.exr"));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(bad + ": "), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("bad.exr")));
}

// glTF carries no sampling setting: rendered with none on the command line, a file renders
// progressively to a default error estimate or a cap, and says so on stderr, on every backend;
// any of --spp, --target-error or --time-limit is the user's choice instead, and says nothing.
TEST(Gltf, AFileWithoutSamplingRendersToADefaultErrorAndSaysSo) {
    TempDir dir;
    GltfBuilder b = cameraAndQuads();
    const std::string glb = b.binary(dir, "model.glb");
    for (const std::string& backend : backendsUnderTest()) {
        SCOPED_TRACE(backend);
        const std::string stats = dir.file(backend + ".json");
        CommandResult r = runSpillway("render " + glb + " --backend " + backend +
                                      " --width 16 --height 8 --quiet -o " +
                                      dir.file(backend + ".exr") + " --stats " + stats);
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_NE(r.output.find(glb + " carries no sampling setting: rendering until the relMSE "
                                      "estimate over the pixels that hold noise reaches 0.002, "
                                      "at most 1024 spp"),
                  std::string::npos)
            << r.output;
        const json s = json::parse(readFile(stats));
        // The stop's rule and what it read, in --stats.
        EXPECT_EQ(s["target_error"]["target"], 0.002) << s.dump();
        EXPECT_NE(s["target_error"]["rule"].get<std::string>().find("pixels that hold noise"),
                  std::string::npos);
        const double fraction = s["target_error"]["subject_fraction"];
        EXPECT_GT(fraction, 0.0);
        EXPECT_LE(fraction, 1.0);
        const std::string reason = s["stop_reason"];
        // 16 samples a pixel an iteration (kGltfSampleBase); the estimate exists from the first.
        EXPECT_EQ(s["iterations"].get<int>() * kGltfSampleBase * kGltfSampleBase, s["spp"])
            << s.dump();
        if (reason == "target error") {
            EXPECT_GE(s["spp"].get<int>(), 16);
            EXPECT_LT(s["spp"].get<int>(), 1024);
        } else {
            EXPECT_EQ(reason, "spp");
            EXPECT_EQ(s["spp"], 1024);
        }
        for (const char* choice : {"--spp 2", "--target-error 0.5", "--time-limit 60"}) {
            r = runSpillway("render " + glb + " --backend " + backend + " " + choice +
                            " --width 16 --height 8 --quiet -o " + dir.file("chosen.exr"));
            ASSERT_EQ(r.status, 0) << choice << ": " << r.output;
            EXPECT_EQ(r.output.find("carries no sampling setting"), std::string::npos) << choice;
        }
    }
}

// A glTF file rendered as the scene takes glTF's Russian roulette (from the second bounce, at
// throughput 0.3), where the YAML format's defaults are the third bounce and 0.1.
TEST(Gltf, AFileRenderedAsTheSceneEndsItsPathsByGltfsRoulette) {
    TempDir dir;
    const Scene scene = loadGltfScene(cameraAndQuads().binary(dir, "model.glb"));
    EXPECT_EQ(scene.settings.minDepth, kGltfMinDepth);
    EXPECT_EQ(scene.settings.threshold, kGltfRouletteThreshold);
    EXPECT_LT(kGltfMinDepth, Settings{}.minDepth);
    EXPECT_GT(kGltfRouletteThreshold, Settings{}.threshold);
}

// `type: Gltf` places a file in a YAML scene: moved by the object's transform, relative to the
// scene's camera; its materials follow the scene's shaders, or `shader:` replaces them all.
TEST(Gltf, AYamlSceneObjectPlacesAFileWithItsMaterialsOrAShader) {
    TempDir dir;
    GltfBuilder b = cameraAndQuads();
    b.embedded(dir, "quads.gltf");
    const std::string head =
        "camera: {type: PinHole, look at: {eye: [0, 0, 10], target: [0, 0, 0]}, "
        "fov: 40}\n"
        "objects:\n";
    const std::string tail = "shaders:\n  - {type: Lambert}\n";
    const Scene own = loadScene(dir.write(
        "own.yaml",
        head + "  - {type: Gltf, filename: quads.gltf, translation: [0, 0, 1]}\n" + tail));
    ASSERT_EQ(own.meshes.size(), 2u);
    EXPECT_EQ(own.objectCount, 2);
    // The file's parent node: scale 2, z + 1; the object: z + 1; camera-relative: z - 10.
    EXPECT_EQ(own.meshes[0].positions[2], vec3(2, 2, -8));
    ASSERT_EQ(own.shaders.size(), 3u); // the scene's Lambert, then the file's two materials
    EXPECT_EQ(own.shaders[0].params.model, kModelLambert);
    EXPECT_EQ(own.shaders[size_t(own.meshes[0].shader)].params.colour, vec3(0.8f, 0.5f, 0.25f));
    EXPECT_GE(own.meshes[1].shader, 1);
    EXPECT_FALSE(own.environment); // a YAML scene lights itself
    // ... and keeps its own settings: the format's Russian roulette, not a glTF file's.
    EXPECT_EQ(own.settings.minDepth, Settings{}.minDepth);
    EXPECT_EQ(own.settings.threshold, Settings{}.threshold);
    ASSERT_EQ(own.warnings.size(), 1u); // the file's camera, not used
    EXPECT_NE(own.warnings[0].find("cameras are not used"), std::string::npos);

    const Scene overridden = loadScene(dir.write(
        "shader.yaml", head + "  - {type: Gltf, filename: quads.gltf, shader: 0}\n" + tail));
    ASSERT_EQ(overridden.shaders.size(), 1u);
    for (const Mesh& m : overridden.meshes)
        EXPECT_EQ(m.shader, 0);
    EXPECT_THROW(loadScene(dir.write("bad.yaml", head +
                                                     "  - {type: Gltf, filename: quads.gltf, "
                                                     "shader: 3}\n" +
                                                     tail)),
                 SceneError);
    EXPECT_THROW(loadScene(dir.write("notgltf.yaml",
                                     head + "  - {type: Gltf, filename: own.yaml}\n" + tail)),
                 SceneError);
}

} // namespace
} // namespace spw::test

namespace spw::test {
namespace {

// The mean of `scene` rendered at 16 x 16 and 4 spp on `backend`.
double meanAt16(Scene scene, BackendKind backend) {
    scene.image.width = scene.image.height = 16;
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = 4;
    const std::vector<float> img = render(scene, cfg)->film->image();
    double sum = 0;
    for (float x : img)
        sum += x;
    return sum / double(img.size());
}

// A 4 x 4 8-bit RGB image of one value.
void writeConstantImage(const std::string& path, vec3 value) {
    OIIO::ImageBuf img(OIIO::ImageSpec(4, 4, 3, OIIO::TypeDesc::UINT8));
    const float v[3] = {value.x, value.y, value.z};
    OIIO::ImageBufAlgo::fill(img, v);
    ASSERT_TRUE(img.write(path));
}

} // namespace
} // namespace spw::test

namespace spw::test {
namespace {

// A unit quad in z = 0 under a slanting directional light, filling the view: with normals
// `normal` everywhere, and a normal map of one texel value `image` unless it is empty. `turned`:
// its texture coordinates a quarter turn round (u along +y, v along -x), so the generated
// tangent frame turns with them. The image's mean.
double tiltedQuadMean(const TempDir& dir, vec3 normal, const std::string& image, float scale,
                      bool turned, BackendKind backend) {
    GltfBuilder b;
    json mat = material(vec3(0.8f), 0.0f, 0.5f);
    if (!image.empty()) {
        mat["normalTexture"] = {{"index", 0}, {"scale", scale}};
        b.doc["textures"] = json::array({{{"source", 0}}});
        b.doc["images"] = json::array({{{"uri", image}}});
    }
    b.doc["materials"] = json::array({mat});
    const int pos = b.accessor<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, 5126, "VEC3");
    std::vector<float> normals;
    for (int i = 0; i < 4; ++i)
        normals.insert(normals.end(), {normal.x, normal.y, normal.z});
    const int nor = b.accessor<float>(normals, 5126, "VEC3");
    // glTF's v runs down: (u, 1 - v) is Spillway's.
    const int uv = b.accessor<float>(turned ? std::vector<float>{0, 0, 0, 1, 1, 1, 1, 0}
                                            : std::vector<float>{0, 1, 1, 1, 1, 0, 0, 0},
                                     5126, "VEC2");
    const int idx = b.accessor<uint16_t>({0, 1, 2, 0, 2, 3}, 5123, "SCALAR");
    const json prim = {{"attributes", {{"POSITION", pos}, {"NORMAL", nor}, {"TEXCOORD_0", uv}}},
                       {"indices", idx},
                       {"material", 0}};
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({{{"type", "directional"}, {"intensity", 2000.0}}});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.25}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    // The light turned from -Z to travel along (0.6, 0.3, -1).
    const vec3 from(0, 0, -1), to = glm::normalize(vec3(0.6f, 0.3f, -1.0f));
    const vec3 axis = glm::cross(from, to);
    const vec4 q = glm::normalize(vec4(axis, 1.0f + glm::dot(from, to)));
    b.scene({b.node({{"mesh", b.mesh(prim)}}),
             b.node({{"camera", 0}, {"translation", {0.5, 0.5, 3}}}),
             b.node({{"rotation", {q.x, q.y, q.z, q.w}},
                     {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
    Scene scene = loadScene(b.embedded(dir, "tilted.gltf"));
    return meanAt16(scene, backend);
}

// normalTexture: a map of one texel value tilts the shading normal as a mesh whose normals
// are that tilt does, in the frame of the texture coordinates (turned with them), with its
// scale, on every backend; the tilts mirrored (a flipped tangent or bitangent) do not.
TEST(Gltf, NormalTexturesTiltTheShadingNormalInTheTextureFrame) {
    TempDir dir;
    const int texel[3] = {200, 90, 220};
    writeConstantImage(dir.file("tilt.png"),
                       vec3(texel[0] / 255.0f, texel[1] / 255.0f, texel[2] / 255.0f));
    const vec3 local(2.0f * texel[0] / 255.0f - 1.0f, 2.0f * texel[1] / 255.0f - 1.0f,
                     2.0f * texel[2] / 255.0f - 1.0f);
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const double flat = tiltedQuadMean(dir, vec3(0, 0, 1), "", 1.0f, false, backend);
        for (float scale : {1.0f, 0.6f})
            for (bool turned : {false, true}) {
                SCOPED_TRACE("scale " + std::to_string(scale) + (turned ? ", turned" : ""));
                const vec3 n(local.x * scale, local.y * scale, local.z);
                // Tangent and bitangent: +x and +y; turned, +y and -x.
                const vec3 world = turned ? vec3(-n.y, n.x, n.z) : n;
                const double mapped =
                    tiltedQuadMean(dir, vec3(0, 0, 1), "tilt.png", scale, turned, backend);
                const double meshed =
                    tiltedQuadMean(dir, glm::normalize(world), "", 1.0f, turned, backend);
                EXPECT_NEAR(mapped, meshed, 2e-3 * meshed);
                EXPECT_GT(std::fabs(mapped - flat), 0.05 * flat);
                for (const vec3 mirrored :
                     {vec3(-world.x, world.y, world.z), vec3(world.x, -world.y, world.z)})
                    EXPECT_GT(std::fabs(mapped - tiltedQuadMean(dir, glm::normalize(mirrored), "",
                                                                1.0f, turned, backend)),
                              0.02 * meshed);
            }
    }
}

// Shading normals bent valid (shared/sampling.h): a large quad whose normals all lean 60 degrees
// toward +x, seen from the -x side 70 degrees off its normal, so that the view direction is below
// every unbent shading normal's hemisphere, under a sun straight above. Unbent, the
// metallic-roughness BSDF is 0 there and the image black; bent, every pixel is lit, on every
// backend.
TEST(Gltf, NormalsTurnedAwayFromTheViewerLeaveNoPixelBlack) {
    TempDir dir;
    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.8f), 0.0f, 0.5f)});
    const int pos =
        b.accessor<float>({-20, -20, 0, 20, -20, 0, 20, 20, 0, -20, 20, 0}, 5126, "VEC3");
    const vec3 lean = glm::normalize(vec3(std::sin(1.0472f), 0.0f, std::cos(1.0472f)));
    std::vector<float> normals;
    for (int i = 0; i < 4; ++i)
        normals.insert(normals.end(), {lean.x, lean.y, lean.z});
    const int nor = b.accessor<float>(normals, 5126, "VEC3");
    const int idx = b.accessor<uint16_t>({0, 1, 2, 0, 2, 3}, 5123, "SCALAR");
    const json prim = {
        {"attributes", {{"POSITION", pos}, {"NORMAL", nor}}}, {"indices", idx}, {"material", 0}};
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({{{"type", "directional"}, {"intensity", 5.0}}});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.2}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    // The camera's -Z turned 70 degrees about +y toward +x, 3 units back from the origin.
    const float t = -1.2217f; // -70 degrees
    const vec3 view(std::sin(1.2217f), 0.0f, -std::cos(1.2217f));
    b.scene({b.node({{"mesh", b.mesh(prim)}}),
             b.node({{"camera", 0},
                     {"rotation", {0.0, std::sin(t / 2), 0.0, std::cos(t / 2)}},
                     {"translation", {-3 * view.x, 0.0, -3 * view.z}}}),
             b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
    Scene scene = loadScene(b.embedded(dir, "leaning.gltf"));
    scene.image.width = scene.image.height = 16;
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        RenderConfig cfg;
        cfg.backend = backend;
        cfg.spp = 1;
        const std::vector<float> img = render(scene, cfg)->film->image();
        float darkest = 1e30f;
        for (size_t p = 0; p < img.size(); p += 3)
            darkest = std::min(darkest, img[p] + img[p + 1] + img[p + 2]);
        EXPECT_GT(darkest, 0.0f);
    }
}

} // namespace
} // namespace spw::test

namespace spw::test {
namespace {

// A view-filling quad of material `mat` under a point light (tiltedQuadMean's view and light),
// the document and its primitive changed by `edit` first (images, vertex colours); its mean at
// 16 x 16 on `backend`.
double quadUnderPointLight(const TempDir& dir, const json& mat,
                           const std::function<void(GltfBuilder&, json&)>& edit,
                           BackendKind backend) {
    GltfBuilder b;
    b.doc["materials"] = json::array({mat});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({{{"type", "point"}, {"intensity", 3000.0}}});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.25}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    json prim = b.quad(0);
    edit(b, prim);
    b.scene({b.node({{"mesh", b.mesh(prim)}}),
             b.node({{"camera", 0}, {"translation", {0.5, 0.5, 3}}}),
             b.node({{"translation", {0.2, 0.7, 1.0}},
                     {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
    Scene scene = loadScene(b.embedded(dir, "lit-quad.gltf"));
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
    return meanAt16(scene, backend);
}

// That quad of base colour (0.9, 0.6, 0.3), metallic and roughness factors, and a
// metallicRoughnessTexture `image` unless it is empty.
double metalRoughQuadMean(const TempDir& dir, float metallic, float roughness,
                          const std::string& image, BackendKind backend) {
    json mat = material(vec3(0.9f, 0.6f, 0.3f), metallic, roughness);
    if (!image.empty()) mat["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", 0}};
    return quadUnderPointLight(
        dir, mat,
        [&](GltfBuilder& b, json&) {
            if (image.empty()) return;
            b.doc["textures"] = json::array({{{"source", 0}}});
            b.doc["images"] = json::array({{{"uri", image}}});
        },
        backend);
}

// metallicRoughnessTexture: its blue channel scales the metallic factor, its green the
// roughness factor, read linearly; an image of one texel value renders as the factors times
// that value do, on every backend, and not as the channels swapped.
TEST(Gltf, MetallicRoughnessTexturesScaleTheFactorsPerHit) {
    TempDir dir;
    const float green = 0.4f, blue = 0.8f; // as 8-bit: 102 / 255 and 204 / 255 exactly
    writeConstantImage(dir.file("mr.png"), vec3(0.1f, green, blue));
    const float metallic = 0.75f, roughness = 0.5f;
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const double mapped = metalRoughQuadMean(dir, metallic, roughness, "mr.png", backend);
        const double factors =
            metalRoughQuadMean(dir, metallic * blue, roughness * green, "", backend);
        const double swapped =
            metalRoughQuadMean(dir, metallic * green, roughness * blue, "", backend);
        const double plain = metalRoughQuadMean(dir, metallic, roughness, "", backend);
        EXPECT_NEAR(mapped, factors, 1e-3 * factors);
        EXPECT_GT(std::fabs(mapped - swapped), 0.05 * factors);
        EXPECT_GT(std::fabs(mapped - plain), 0.05 * factors);
    }
}

} // namespace
} // namespace spw::test

namespace spw::test {
namespace {

// A white floor (4 x 4, z = 0) under a two-sided emitting unit quad at z = 1 whose emission is
// emissiveFactor 1 x strength 4 x the image `image` (none: the factor alone, times `scale`),
// seen from above; 24 x 24 pixels, the quad in columns and rows 7.2-16.8, the image's left half
// on the left.
std::vector<float> renderEmissiveQuad(const TempDir& dir, const std::string& image, float scale,
                                      BackendKind backend, uint strategy = kStrategyMis,
                                      int spp = 16, const json& sampler = json()) {
    GltfBuilder b;
    json light = material(vec3(0.0f), 0.0f, 1.0f, vec3(scale));
    light["doubleSided"] = true;
    light["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = 4.0;
    if (!image.empty()) {
        light["emissiveTexture"] = {{"index", 0}};
        b.doc["textures"] = json::array({{{"source", 0}}});
        b.doc["images"] = json::array({{{"uri", image}}});
    }
    if (!sampler.is_null()) { // and u stretched to 3u - 1, so that it reads beyond the image
        light["emissiveTexture"]["extensions"]["KHR_texture_transform"] = {{"offset", {-1.0, 0.0}},
                                                                           {"scale", {3.0, 1.0}}};
        b.doc["samplers"] = json::array({sampler});
        b.doc["textures"][0]["sampler"] = 0;
        b.doc["extensionsUsed"].push_back("KHR_texture_transform");
    }
    b.doc["materials"] = json::array({material(vec3(0.8f), 0.0f, 1.0f), light});
    b.doc["extensionsUsed"].push_back("KHR_materials_emissive_strength");
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.6}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene(
        {b.node(
             {{"mesh", b.mesh(b.quad(0))}, {"scale", {4, 4, 4}}, {"translation", {-1.5, -1.5, 0}}}),
         b.node({{"mesh", b.mesh(b.quad(1))}, {"translation", {0, 0, 1}}}),
         b.node({{"camera", 0}, {"translation", {0.5, 0.5, 5}}})});
    Scene scene = loadScene(b.embedded(dir, "emissive.gltf"));
    // The quad alone lights the floor, however dim its image makes it (as --environment 0,0,0
    // asks; GltfLighting.* tests the default).
    for (const std::string& w : scene.warnings)
        EXPECT_NE(w.find("lit by that environment as well"), std::string::npos) << w;
    scene.environment.reset();
    scene.image.width = scene.image.height = 24;
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = spp;
    cfg.strategy = strategy;
    return render(scene, cfg)->film->image();
}

// The mean of pixels [x0, x1) x [y0, y1) of a 24 x 24 image.
double rectMean(const std::vector<float>& img, int x0, int x1, int y0, int y1) {
    double sum = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            for (int c = 0; c < 3; ++c)
                sum += img[size_t(y * 24 + x) * 3 + size_t(c)];
    return sum / (double(y1 - y0) * double(x1 - x0) * 3.0);
}

// The whole image's mean.
double imageMean(const std::vector<float>& img) {
    return rectMean(img, 0, 24, 0, 24);
}

// emissiveTexture: the image times the factor is the radiance at each point of the emitter, seen
// by rays that hit it and by next-event estimation alike, on every backend. An image of one value
// renders as the factor times that value does; an image half black is black where the camera
// sees that half (and so is one beyond 2048 x 2048 texels, averaged down first), and light
// sampling and BSDF sampling alone agree on the floor it lights.
TEST(Gltf, EmissiveTexturesScaleTheEmissionWhereverItIsSampled) {
    TempDir dir;
    const float grey = 0.4f; // as 8-bit sRGB: 102 / 255, linearised
    writeConstantImage(dir.file("grey.png"), vec3(grey));
    const float linear = srgbToLinear(102.0f / 255.0f);
    OIIO::ImageBuf half(OIIO::ImageSpec(64, 4, 3, OIIO::TypeDesc::UINT8));
    const float white[3] = {1.0f, 1.0f, 1.0f};
    OIIO::ImageBufAlgo::fill(half, white, OIIO::ROI(0, 32, 0, 4, 0, 1, 0, 3));
    ASSERT_TRUE(half.write(dir.file("half.png")));
    // Beyond 2048 x 2048 texels, averaged down 2 x 2 (to 1025 x 1025) before baking.
    OIIO::ImageBuf large(OIIO::ImageSpec(2050, 2050, 3, OIIO::TypeDesc::UINT8));
    OIIO::ImageBufAlgo::fill(large, white, OIIO::ROI(0, 1025, 0, 2050, 0, 1, 0, 3));
    ASSERT_TRUE(large.write(dir.file("large.png")));
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const double mapped = imageMean(renderEmissiveQuad(dir, "grey.png", 1.0f, backend));
        const double factor = imageMean(renderEmissiveQuad(dir, "", linear, backend));
        const double plain = imageMean(renderEmissiveQuad(dir, "", 1.0f, backend));
        EXPECT_NEAR(mapped, factor, 1e-4 * factor);
        EXPECT_GT(plain, 1.5 * mapped);

        // The camera sees the image's white half at 4 (and no MIS weight at the first hit), its
        // black half at 0.
        const std::vector<float> halved = renderEmissiveQuad(dir, "half.png", 1.0f, backend);
        EXPECT_NEAR(rectMean(halved, 8, 11, 8, 16), 4.0, 1e-3);
        EXPECT_NEAR(rectMean(halved, 13, 16, 8, 16), 0.0, 1e-3);
        const std::vector<float> large = renderEmissiveQuad(dir, "large.png", 1.0f, backend);
        EXPECT_NEAR(rectMean(large, 8, 11, 8, 16), 4.0, 1e-3);
        EXPECT_NEAR(rectMean(large, 13, 16, 8, 16), 0.0, 1e-3);
        // u read from 3u - 1 under a clamping sampler: the white edge texel left of the image
        // (columns 8-10: u' -0.7 .. 0.2), the black one right of it (13-15: 0.8 .. 1.7); and
        // light sampling finds the same clamped panel as BSDF sampling.
        const json clamping = {{"wrapS", 33071}, {"wrapT", 33071}};
        const std::vector<float> clamped =
            renderEmissiveQuad(dir, "half.png", 1.0f, backend, kStrategyMis, 16, clamping);
        EXPECT_NEAR(rectMean(clamped, 8, 11, 8, 16), 4.0, 1e-3);
        EXPECT_NEAR(rectMean(clamped, 13, 16, 8, 16), 0.0, 1e-3);
        // The floor around the quad, lit by its underside: what light sampling alone finds
        // agrees with what BSDF sampling alone finds (at 256 spp; at 16, BSDF sampling alone is
        // 11 % off, with or without the map), and with both, and is half what the whole quad
        // gives.
        const auto floorMean = [](const std::vector<float>& img) {
            return (rectMean(img, 0, 24, 0, 6) + rectMean(img, 0, 24, 19, 24)) / 2.0;
        };
        const double byLight =
            floorMean(renderEmissiveQuad(dir, "half.png", 1.0f, backend, kStrategyLight, 256));
        const double byBsdf =
            floorMean(renderEmissiveQuad(dir, "half.png", 1.0f, backend, kStrategyBsdf, 256));
        const double byBoth =
            floorMean(renderEmissiveQuad(dir, "half.png", 1.0f, backend, kStrategyMis, 256));
        const double whole =
            floorMean(renderEmissiveQuad(dir, "", 1.0f, backend, kStrategyMis, 256));
        EXPECT_NEAR(byLight, byBsdf, 0.02 * byBsdf);
        const auto floorOf = [&](uint strategy) {
            return floorMean(
                renderEmissiveQuad(dir, "half.png", 1.0f, backend, strategy, 256, clamping));
        };
        EXPECT_NEAR(floorOf(kStrategyLight), floorOf(kStrategyBsdf), 0.02 * floorOf(kStrategyBsdf));
        EXPECT_NEAR(byBoth, byLight, 0.02 * byLight);
        EXPECT_NEAR(byBoth, 0.5 * whole, 0.03 * byBoth);
    }
}

} // namespace
} // namespace spw::test

namespace spw::test {
namespace {

// COLOR_0 multiplies the base colour, per vertex, interpolated across the triangles, on every
// backend: a quad whose four vertices carry one colour renders as its base colour times that
// colour does, whether the colours are floats (RGB) or normalized bytes or shorts (RGBA, the
// alpha not read); and not as the colours' channels reversed.
TEST(Gltf, VertexColoursScaleTheBaseColour) {
    TempDir dir;
    const vec3 factor(0.9f, 0.6f, 0.3f), colour(0.4f, 0.8f, 0.2f);
    const auto floats = [&](GltfBuilder& b, json& prim) {
        std::vector<float> c;
        for (int i = 0; i < 4; ++i)
            c.insert(c.end(), {colour.x, colour.y, colour.z});
        prim["attributes"]["COLOR_0"] = b.accessor<float>(c, 5126, "VEC3");
    };
    const auto bytes = [&](GltfBuilder& b, json& prim) { // 102, 204, 51: exactly the colour
        std::vector<uint8_t> c;
        for (int i = 0; i < 4; ++i)
            for (uint8_t v : {102, 204, 51, 7}) // (insert() of a list: a GCC 12 false warning)
                c.push_back(v);
        prim["attributes"]["COLOR_0"] = b.accessor<uint8_t>(c, 5121, "VEC4", true);
    };
    const auto shorts = [&](GltfBuilder& b, json& prim) { // 0.4, 0.8, 0.2 of 65535
        std::vector<uint16_t> c;
        for (int i = 0; i < 4; ++i)
            c.insert(c.end(), {26214, 52428, 13107, 0});
        prim["attributes"]["COLOR_0"] = b.accessor<uint16_t>(c, 5123, "VEC4", true);
    };
    const auto none = [](GltfBuilder&, json&) {};
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const double product =
            quadUnderPointLight(dir, material(factor * colour, 0.0f, 1.0f), none, backend);
        const double reversed = quadUnderPointLight(
            dir, material(factor * vec3(colour.z, colour.y, colour.x), 0.0f, 1.0f), none, backend);
        using Edit = std::function<void(GltfBuilder&, json&)>;
        for (const Edit& edit : {Edit(floats), Edit(bytes), Edit(shorts)})
            EXPECT_NEAR(quadUnderPointLight(dir, material(factor, 0.0f, 1.0f), edit, backend),
                        product, 1e-4 * product);
        EXPECT_GT(std::fabs(reversed - product), 0.05 * product);
    }
}

// A sparse accessor: its indices' elements replaced by its values, over a buffer view or over
// zeros; the quad it makes renders as the plain quad, to the bit. An index past the count is
// an error naming the accessor's sparse indices.
TEST(Gltf, SparseAccessorsSubstituteTheirValues) {
    TempDir dir;
    const auto plainQuad = [&](const std::string& name,
                               const std::function<void(GltfBuilder&, json&)>& edit) {
        GltfBuilder b;
        b.doc["materials"] = json::array({material(vec3(0.8f), 0.0f, 1.0f)});
        json prim = b.quad(0);
        edit(b, prim);
        b.doc["cameras"] =
            json::array({{{"type", "perspective"},
                          {"perspective", {{"yfov", 0.6}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
        b.scene({b.node({{"mesh", b.mesh(prim)}}),
                 b.node({{"camera", 0}, {"translation", {0.5, 0.5, 3}}})});
        return b.embedded(dir, name);
    };
    // Vertex 2 stored at (5, 5, 0), put back at (1, 1, 0) by the sparse part.
    const auto overView = [](GltfBuilder& b, json& prim) {
        const int pos = b.accessor<float>({0, 0, 0, 1, 0, 0, 5, 5, 0, 0, 1, 0}, 5126, "VEC3");
        b.doc["accessors"][size_t(pos)]["sparse"] = {
            {"count", 1},
            {"indices", {{"bufferView", b.view<uint16_t>({2})}, {"componentType", 5123}}},
            {"values", {{"bufferView", b.view<float>({1, 1, 0})}}}};
        prim["attributes"]["POSITION"] = pos;
    };
    // No buffer view: zeros, the three vertices off the origin substituted.
    const auto overZeros = [](GltfBuilder& b, json& prim) {
        const int pos = b.accessor<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, 5126, "VEC3");
        b.doc["accessors"][size_t(pos)].erase("bufferView");
        b.doc["accessors"][size_t(pos)]["sparse"] = {
            {"count", 3},
            {"indices", {{"bufferView", b.view<uint8_t>({1, 2, 3, 0})}, {"componentType", 5121}}},
            {"values", {{"bufferView", b.view<float>({1, 0, 0, 1, 1, 0, 0, 1, 0})}}}};
        prim["attributes"]["POSITION"] = pos;
    };
    const auto pastTheEnd = [](GltfBuilder& b, json& prim) {
        const int pos = b.accessor<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, 5126, "VEC3");
        b.doc["accessors"][size_t(pos)]["sparse"] = {
            {"count", 1},
            {"indices", {{"bufferView", b.view<uint32_t>({4})}, {"componentType", 5125}}},
            {"values", {{"bufferView", b.view<float>({1, 1, 0})}}}};
        prim["attributes"]["POSITION"] = pos;
    };
    const std::string plain = plainQuad("plain.gltf", [](GltfBuilder&, json&) {});
    Scene reference = loadScene(plain);
    using Edit = std::function<void(GltfBuilder&, json&)>;
    for (const Edit& edit : {Edit(overView), Edit(overZeros)}) {
        Scene sparse = loadScene(plainQuad("sparse.gltf", edit));
        EXPECT_EQ(sparse.meshes.at(0).positions, reference.meshes.at(0).positions);
        EXPECT_EQ(meanAt16(sparse, BackendKind::Cpu), meanAt16(reference, BackendKind::Cpu));
    }
    const std::string bad = plainQuad("bad-sparse.gltf", pastTheEnd);
    try {
        loadScene(bad);
        ADD_FAILURE() << "loaded";
    } catch (const SceneError& e) {
        EXPECT_NE(
            std::string(e.what()).find("/sparse/indices: index 4 is past the accessor's count 4"),
            std::string::npos)
            << e.what();
    }
}

} // namespace
} // namespace spw::test
