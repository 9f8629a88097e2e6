// The scene loader against docs/scene-format.md: the thesis' Appendix B example loads as written,
// every class of bad input stops the program with "file:line:" and exit status 2 before anything
// is rendered, a scene without entries takes the documented defaults, and transforms compose as
// specified (scale, then R = Rz*Ry*Rx, then translation).
#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

// A 4x4 RGB float image; OpenImageIO writes a ".tx" path as TIFF.
void writeTexture(const std::string& path, float value) {
    fs::create_directories(fs::path(path).parent_path());
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::FLOAT);
    std::vector<float> pixels(4 * 4 * 3, value);
    ASSERT_TRUE(out->open(path, spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
    ASSERT_TRUE(out->close()) << out->geterror();
}

// One triangle with corners on the three axes, wound so that its normal is (1, 1, 1).
const char* kTriangleObj = "v 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n";

// A unit square in the XZ plane facing +Y, with texture coordinates.
const char* kModelObj = "v -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\n"
                        "vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n"
                        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";

// Appendix B of the thesis, verbatim but for the object's rotation, which the text extraction
// turned into LaTeX. Note the two top-level `light:` keys.
const char* kAppendixB = R"(image:
  width: 1024
  height: 429
  sample base: 1
settings:
  min depth: 2
  max depth: 5
  threshold: 0.1
  bucket size: 32
  shading size: 4096
  bin exponent: 15
camera:
  type: PinHole
  translation: [ 0, 120, 1000 ]
  rotation: [0, 90, -3]
  focal length: 150
filter:
  type: Tent
sampler:
  type: Stratified
object:
  type: Polygon
  filename: objects/model.obj
  translation: [15, 0, 25]
  rotation: [0, 45, 0]
  scale: [10, 10, 10]
  shader: 0
shader:
  type: Lambert
  reflectance: 0.3
  texture:
    type: Layered
    upper:
      type: Standard
      string: textures/texture_one.tx
    lower:
      type: Standard
      string: textures/texture_two.tx
    mask:
      type: Constant
      colour: [0.5, 0.5, 0.5]
light:
  type: Quad
  translation: [ 100, 100, 35 ]
  rotation: [0, 135, -25]
  scale: [ 50, 50 ]
  intensity: 25
light:
  type: Quad
  translation: [-120, 120, 50]
  rotation: [0, 45, -25]
  scale: [ 100, 100 ]
  intensity: 1
)";

vec3 centroid(const Mesh& m) {
    vec3 c(0.0f);
    for (vec3 p : m.positions)
        c += p;
    return c / float(m.positions.size());
}

void expectNear(vec3 actual, vec3 expected, float tolerance, const std::string& what) {
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(actual[i], expected[i], tolerance) << what << ", component " << i;
}

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() &&
           s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

TEST(Loader, AppendixBExampleLoads) {
    TempDir dir;
    dir.write("objects/model.obj", kModelObj);
    writeTexture(dir.file("textures/texture_one.tx"), 0.8f);
    writeTexture(dir.file("textures/texture_two.tx"), 0.2f);
    Scene scene = loadScene(dir.write("appendix_b.yaml", kAppendixB));

    EXPECT_EQ(scene.image.width, 1024);
    EXPECT_EQ(scene.image.height, 429);
    EXPECT_EQ(scene.image.sampleBase, 1);
    EXPECT_EQ(scene.settings.minDepth, 2);
    EXPECT_EQ(scene.settings.maxDepth, 5);
    EXPECT_FLOAT_EQ(scene.settings.threshold, 0.1f);
    EXPECT_EQ(scene.settings.bucketSize, 32);
    EXPECT_EQ(scene.settings.shadingSize, 4096);
    EXPECT_EQ(scene.settings.binExponent, 15);
    EXPECT_EQ(scene.camera.type, CameraType::PinHole);
    EXPECT_FLOAT_EQ(scene.camera.focalLength, 150.0f);
    // The world is camera-relative: the camera's position is the scene's origin.
    expectNear(vec3(scene.origin), vec3(0, 120, 1000), 1e-4f, "camera position");
    expectNear(vec3(scene.camera.cameraToWorld[3]), vec3(0.0f), 0.0f,
               "camera position in the rendered world");
    EXPECT_EQ(scene.filter.type, FilterType::Tent);
    EXPECT_EQ(scene.sampler, SamplerType::Stratified);

    // One object, one scene shader, and both `light:` entries, in file order.
    ASSERT_EQ(scene.objectCount, 1);
    ASSERT_EQ(scene.quadLightCount, 2);
    ASSERT_EQ(scene.meshes.size(), 3u);
    ASSERT_EQ(scene.shaders.size(), 3u); // the Lambert, then one emissive Null per quad light
    EXPECT_EQ(scene.meshes[0].triangles.size(), 2u);
    EXPECT_EQ(scene.meshes[0].uvs.size(), scene.meshes[0].positions.size());
    EXPECT_EQ(scene.meshes[0].shader, 0);
    expectNear(vec3(scene.origin) + centroid(scene.meshes[1]), vec3(100, 100, 35), 1e-3f,
               "first light");
    expectNear(vec3(scene.origin) + centroid(scene.meshes[2]), vec3(-120, 120, 50), 1e-3f,
               "second light");
    expectNear(scene.shaders[size_t(scene.meshes[1].shader)].params.emission, vec3(25.0f), 0.0f,
               "first light emission");
    expectNear(scene.shaders[size_t(scene.meshes[2].shader)].params.emission, vec3(1.0f), 0.0f,
               "second light emission");

    const Shader& lambert = scene.shaders[0];
    EXPECT_EQ(lambert.typeName, "Lambert");
    EXPECT_FLOAT_EQ(lambert.params.reflectance, 0.3f);
    ASSERT_EQ(scene.textures.size(), 4u);
    ASSERT_GE(lambert.texture, 0);
    const Texture& root = scene.textures[size_t(lambert.texture)];
    ASSERT_EQ(root.type, TextureType::Layered);
    const Texture& upper = scene.textures[size_t(root.upper)];
    const Texture& lower = scene.textures[size_t(root.lower)];
    const Texture& mask = scene.textures[size_t(root.mask)];
    EXPECT_EQ(upper.type, TextureType::Standard);
    EXPECT_TRUE(endsWith(upper.path, "textures/texture_one.tx")) << upper.path;
    EXPECT_EQ(lower.type, TextureType::Standard);
    EXPECT_TRUE(endsWith(lower.path, "textures/texture_two.tx")) << lower.path;
    EXPECT_EQ(mask.type, TextureType::Constant);
    expectNear(mask.colour, vec3(0.5f), 0.0f, "mask colour");
    EXPECT_TRUE(scene.usesTextures());

    // And it renders: a small film, one sample a pixel, nothing but finite values.
    scene.image.width = 32;
    scene.image.height = 16;
    RenderConfig config;
    config.spp = 1;
    auto result = render(scene, config);
    std::vector<float> image = result->film->image();
    ASSERT_EQ(image.size(), 32u * 16u * 3u);
    for (float v : image)
        ASSERT_TRUE(std::isfinite(v));
    EXPECT_EQ(result->stats.nonFiniteSamples, 0u);
}

TEST(Loader, EmptyFileTakesTheDocumentedDefaults) {
    TempDir dir;
    Scene scene = loadScene(dir.write("empty.yaml", ""));
    EXPECT_EQ(scene.image.width, 512);
    EXPECT_EQ(scene.image.height, 512);
    EXPECT_EQ(scene.image.sampleBase, 1);
    EXPECT_EQ(scene.image.iterations, 1);
    EXPECT_EQ(scene.settings.minDepth, 3);
    EXPECT_EQ(scene.settings.maxDepth, 16);
    EXPECT_FLOAT_EQ(scene.settings.threshold, 0.1f);
    EXPECT_EQ(scene.settings.bucketSize, 32);
    EXPECT_EQ(scene.settings.shadingSize, 4096);
    EXPECT_EQ(scene.settings.binExponent, 15);
    EXPECT_DOUBLE_EQ(scene.settings.memoryBudgetMiB, 512.0);
    EXPECT_DOUBLE_EQ(scene.settings.textureCacheMiB, 1024.0);
    EXPECT_EQ(scene.settings.seed, 0u);
    EXPECT_EQ(scene.camera.type, CameraType::PinHole);
    EXPECT_FLOAT_EQ(scene.camera.focalLength, 35.0f);
    EXPECT_FLOAT_EQ(scene.camera.filmWidth, 35.0f);
    EXPECT_FALSE(scene.camera.fovDegrees.has_value());
    EXPECT_EQ(scene.filter.type, FilterType::Box);
    EXPECT_EQ(scene.sampler, SamplerType::Sobol);
    EXPECT_TRUE(scene.meshes.empty());
    EXPECT_TRUE(scene.shaders.empty());
    EXPECT_EQ(scene.objectCount, 0);
    EXPECT_EQ(scene.quadLightCount, 0);

    scene.image.width = 16;
    scene.image.height = 16;
    RenderConfig config;
    config.spp = 1;
    auto result = render(scene, config);
    std::vector<float> image = result->film->image();
    ASSERT_EQ(image.size(), 16u * 16u * 3u);
    for (float v : image)
        ASSERT_EQ(v, 0.0f);
}

TEST(Loader, CommentOnlyFileIsAnEmptyScene) {
    TempDir dir;
    Scene scene = loadScene(dir.write("comment.yaml", "# nothing here yet\n"));
    EXPECT_EQ(scene.image.width, 512);
    EXPECT_TRUE(scene.meshes.empty());
}

TEST(Loader, PluralAndSingularKeysLoadInFileOrder) {
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    const char* text = R"(shaders:
  - {type: Lambert, reflectance: 0.1}
  - {type: Lambert, reflectance: 0.2}
shader: {type: Lambert, reflectance: 0.3}
objects:
  - {filename: tri.obj, shader: 2}
object: {filename: tri.obj, shader: 0, translation: [0, 5, 0]}
lights:
  - {type: Quad, intensity: 2}
light: {type: Quad, intensity: 3}
shaders:
  - {type: Emissive, emission: [4, 4, 4]}
objects:
  - {filename: tri.obj, shader: 3, translation: [0, 9, 0]}
lights:
  - {type: Quad, intensity: 5}
)";
    Scene scene = loadScene(dir.write("mixed.yaml", text));
    ASSERT_EQ(scene.objectCount, 3);
    ASSERT_EQ(scene.quadLightCount, 3);
    ASSERT_EQ(scene.shaders.size(), 4u + 3u);
    EXPECT_FLOAT_EQ(scene.shaders[0].params.reflectance, 0.1f);
    EXPECT_FLOAT_EQ(scene.shaders[1].params.reflectance, 0.2f);
    EXPECT_FLOAT_EQ(scene.shaders[2].params.reflectance, 0.3f);
    EXPECT_EQ(scene.shaders[3].typeName, "Emissive");
    expectNear(scene.shaders[3].params.emission, vec3(4.0f), 0.0f, "Emissive shader");

    EXPECT_EQ(scene.meshes[0].shader, 2);
    EXPECT_EQ(scene.meshes[1].shader, 0);
    EXPECT_EQ(scene.meshes[2].shader, 3);
    EXPECT_NEAR(centroid(scene.meshes[0]).y, 1.0f / 3.0f, 1e-5f);
    EXPECT_NEAR(centroid(scene.meshes[1]).y, 5.0f + 1.0f / 3.0f, 1e-5f);
    EXPECT_NEAR(centroid(scene.meshes[2]).y, 9.0f + 1.0f / 3.0f, 1e-5f);

    const float intensities[] = {2.0f, 3.0f, 5.0f};
    for (int i = 0; i < 3; ++i) {
        const Mesh& light = scene.meshes[size_t(scene.objectCount + i)];
        ASSERT_GE(light.shader, 4) << "light " << i << " must use a shader after the scene's";
        expectNear(scene.shaders[size_t(light.shader)].params.emission, vec3(intensities[i]), 0.0f,
                   "light " + std::to_string(i));
    }
}

// scale [2, 3, 4], rotation [90, 90, 90] (R = Rz*Ry*Rx), translation [1, 2, 3], worked by hand:
//   (1,0,0) -> scale (2,0,0) -> Rx (2,0,0)  -> Ry (0,0,-2) -> Rz (0,0,-2) -> (1,2,1)
//   (0,1,0) -> scale (0,3,0) -> Rx (0,0,3)  -> Ry (3,0,0)  -> Rz (0,3,0)  -> (1,5,3)
//   (0,0,1) -> scale (0,0,4) -> Rx (0,-4,0) -> Ry (0,-4,0) -> Rz (4,0,0)  -> (5,2,3)
// Rx*Ry*Rz would send the first corner to (1,2,5); rotating before scaling, to (1,2,-1).
TEST(Loader, ObjectTransformScalesThenRotatesZYXThenTranslates) {
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    Scene scene =
        loadScene(dir.write("xf.yaml", "shader: {type: Lambert}\n"
                                       "object: {filename: tri.obj, scale: [2, 3, 4], rotation: "
                                       "[90, 90, 90], translation: [1, 2, 3]}\n"));
    ASSERT_EQ(scene.objectCount, 1);
    const Mesh& m = scene.meshes[0];
    ASSERT_EQ(m.triangles.size(), 1u);
    const uvec3 t = m.triangles[0];
    expectNear(m.positions[t.x], vec3(1, 2, 1), 1e-5f, "corner (1,0,0)");
    expectNear(m.positions[t.y], vec3(1, 5, 3), 1e-5f, "corner (0,1,0)");
    expectNear(m.positions[t.z], vec3(5, 2, 3), 1e-5f, "corner (0,0,1)");
}

TEST(Loader, UniformScaleIsANumber) {
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    Scene scene = loadScene(dir.write("xf.yaml", "shader: {type: Lambert}\nobject: {filename: "
                                                 "tri.obj, scale: 3, translation: [0, 0, -1]}\n"));
    const Mesh& m = scene.meshes[0];
    const uvec3 t = m.triangles[0];
    expectNear(m.positions[t.x], vec3(3, 0, -1), 1e-5f, "corner (1,0,0)");
    expectNear(m.positions[t.y], vec3(0, 3, -1), 1e-5f, "corner (0,1,0)");
    expectNear(m.positions[t.z], vec3(0, 0, 2), 1e-5f, "corner (0,0,1)");
}

// A mirroring transform keeps the file's front faces (as glTF's loader and a mirroring instance
// do): the triangle's corners are taken in turned order, so cross(e1, e2) is the file's normal
// mirrored, not its opposite. A one-sided emitter or a glass placed mirrored faces as the file
// says.
TEST(Loader, AMirroredObjectKeepsItsFrontFaces) {
    TempDir dir;
    dir.write("tri.obj", kTriangleObj); // corners (1,0,0), (0,1,0), (0,0,1): normal (1,1,1)
    for (const char* scale : {"[1, 1, 1]", "[-1, 1, 1]", "[-1, -1, 1]", "[1, 1, -2]"}) {
        const Scene scene = loadScene(dir.write(
            "m.yaml", std::string("shader: {type: Lambert}\nobject: {filename: tri.obj, scale: ") +
                          scale + "}\n"));
        const Mesh& m = scene.meshes[0];
        const uvec3 t = m.triangles[0];
        const vec3 n =
            glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]);
        const vec3 corner = m.positions[t.x] + m.positions[t.y] + m.positions[t.z];
        EXPECT_GT(glm::dot(n, corner), 0.0f) << scale; // still facing away from the origin
    }
}

// Conductor and Dielectric: their keys, defaults (colour 1, alpha 0; ior 1.5, alpha 0) and
// the models they select.
// YAML reads a plain `Null` as the null value: the format's Null shader must load all the same.
TEST(Loader, NullShaderTypeIsReadAsTheNullShader) {
    TempDir dir;
    const Scene scene = loadScene(
        dir.write("n.yaml", "shaders:\n  - {type: Null, emission: [2, 2, 2]}\n  - type: Null\n"));
    ASSERT_EQ(scene.shaders.size(), 2u);
    for (const Shader& s : scene.shaders)
        EXPECT_EQ(s.params.model, kModelNull);
    EXPECT_EQ(scene.shaders[0].params.emission, vec3(2.0f));
}

// A YAML anchor used many times is one texture, not a copy per use: 30 levels each using the
// level below three times load as 31 textures (3^30 leaves if aliases were copied).
TEST(Loader, TextureAliasesAreSharedNotCopied) {
    TempDir dir;
    std::string y =
        "shaders:\n  - {type: Lambert, texture: &a0 {type: Constant, colour: [0.5, 0.5, 0.5]}}\n";
    for (int i = 1; i <= 30; ++i) {
        const std::string prev = "*a" + std::to_string(i - 1);
        y += "  - {type: Lambert, texture: &a" + std::to_string(i) +
             " {type: Layered, upper: " + prev + ", lower: " + prev + ", mask: " + prev + "}}\n";
    }
    const Scene scene = loadScene(dir.write("bomb.yaml", y));
    EXPECT_EQ(scene.textures.size(), 31u);
    ASSERT_EQ(scene.shaders.size(), 31u);
    const Texture& top = scene.textures[size_t(scene.shaders[30].texture)];
    EXPECT_EQ(top.upper, top.lower);
    EXPECT_EQ(top.upper, top.mask);
}

TEST(Loader, ConductorAndDielectricTakeTheirKeysAndDefaults) {
    TempDir dir;
    Scene scene = loadScene(
        dir.write("metal.yaml",
                  "shaders:\n"
                  "  - {type: Conductor}\n"
                  "  - {type: Conductor, colour: [0.9, 0.6, 0.2], alpha: 0.3, two sided: true}\n"
                  "  - {type: Dielectric}\n"
                  "  - {type: Dielectric, ior: 2.4, alpha: 0.05, emission: [1, 2, 3]}\n"));
    ASSERT_EQ(scene.shaders.size(), 4u);
    const ShaderParams& c0 = scene.shaders[0].params;
    EXPECT_EQ(c0.model, kModelConductor);
    expectNear(c0.colour, vec3(1.0f), 0.0f, "default F0");
    EXPECT_EQ(c0.alpha, 0.0f);
    const ShaderParams& c1 = scene.shaders[1].params;
    expectNear(c1.colour, vec3(0.9f, 0.6f, 0.2f), 0.0f, "F0");
    EXPECT_FLOAT_EQ(c1.alpha, 0.3f);
    EXPECT_TRUE(c1.flags & kShaderTwoSided);
    const ShaderParams& d0 = scene.shaders[2].params;
    EXPECT_EQ(d0.model, kModelDielectric);
    EXPECT_FLOAT_EQ(d0.ior, 1.5f);
    EXPECT_EQ(d0.alpha, 0.0f);
    const ShaderParams& d1 = scene.shaders[3].params;
    EXPECT_FLOAT_EQ(d1.ior, 2.4f);
    EXPECT_FLOAT_EQ(d1.alpha, 0.05f);
    expectNear(d1.emission, vec3(1, 2, 3), 0.0f, "emission");
}

// Zero-area triangles are dropped, and the CLI says so once per file, naming it and the count.
TEST(Loader, DegenerateTrianglesAreDroppedWithOneWarning) {
    TempDir dir;
    const std::string obj = dir.write("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
                                                        "f 1 2 3\nf 1 2 4\nf 1 1 3\n");
    Scene scene = loadScene(
        dir.write("d.yaml", "shader: {type: Lambert}\nobject: {filename: degenerate.obj}\n"));
    ASSERT_EQ(scene.meshes.size(), 1u);
    EXPECT_EQ(scene.meshes[0].triangles.size(), 1u);
    EXPECT_EQ(scene.meshes[0].droppedTriangles, 2);
    CommandResult r = runSpillway("render " + dir.file("d.yaml") + " -o " + dir.file("d.exr") +
                                  " --quiet --spp 1 --backend reference");
    EXPECT_EQ(r.status, 0) << r.output;
    const std::string warning = "degenerate.obj: dropped 2 zero-area triangles";
    const size_t at = r.output.find(warning);
    EXPECT_NE(at, std::string::npos) << r.output;
    EXPECT_EQ(r.output.find(warning, at + 1), std::string::npos) << "warned twice: " << r.output;
    EXPECT_NE(r.output.find(obj), std::string::npos)
        << "the warning must name the file: " << r.output;
}

// Absurd --spp values are refused before anything is loaded or allocated.
TEST(Loader, AbsurdSppIsAUsageError) {
    TempDir dir;
    const std::string scene = dir.write("s.yaml", "image: {width: 4, height: 4}\n");
    for (const char* spp : {"0", "-3", "100000000000", "1e9"}) {
        CommandResult r =
            runSpillway("render " + scene + " -o " + dir.file("s.exr") + " --quiet --spp " + spp);
        EXPECT_EQ(r.status, 2) << spp << ": " << r.output;
        EXPECT_NE(r.output.find("--spp"), std::string::npos) << r.output;
    }
}

// The unit square in local XY, scaled by [4, 2], turned by 90 degrees about X: it lies in the
// plane y = 5, spans 4 in X and 2 in Z, and its front (local +Z) faces -Y.
TEST(Loader, QuadLightRotatedNinetyAboutXFacesDown) {
    TempDir dir;
    Scene scene = loadScene(dir.write(
        "light.yaml",
        "light: {type: Quad, translation: [1, 5, -3], rotation: [90, 0, 0], scale: [4, 2]}\n"));
    ASSERT_EQ(scene.quadLightCount, 1);
    const Mesh& m = scene.meshes[size_t(scene.objectCount)];
    ASSERT_EQ(m.triangles.size(), 2u);
    for (const uvec3& t : m.triangles) {
        vec3 n =
            glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]);
        expectNear(glm::normalize(n), vec3(0, -1, 0), 1e-5f, "triangle normal");
    }
    vec3 lo(HUGE_VALF), hi(-HUGE_VALF);
    for (vec3 p : m.positions)
        lo = glm::min(lo, p), hi = glm::max(hi, p);
    expectNear(lo, vec3(-1, 5, -4), 1e-5f, "lower corner");
    expectNear(hi, vec3(3, 5, -2), 1e-5f, "upper corner");
}

TEST(Loader, PointAndEnvironmentLightsAddNoShaderOrObject) {
    TempDir dir;
    writeImage(dir.file("sky.exr"), ImageRGB{4, 2, std::vector<float>(24, 0.25f)});
    Scene scene = loadScene(
        dir.write("lights.yaml",
                  "camera: {look at: {eye: [1, 0, 0], target: [0, 0, 0]}}\n"
                  "lights:\n"
                  "  - {type: Point, position: [1, 5, -3], intensity: 2, colour: [1, 0.5, 0]}\n"
                  "  - {type: Environment, string: sky.exr, intensity: 4}\n"));
    EXPECT_TRUE(scene.shaders.empty());
    EXPECT_TRUE(scene.meshes.empty());
    ASSERT_EQ(scene.punctualLights.size(), 1u);
    // Camera-relative, as all geometry.
    expectNear(scene.punctualLights[0].position, vec3(0, 5, -3), 1e-6f, "position");
    expectNear(scene.punctualLights[0].intensity, vec3(2, 1, 0), 0.0f, "intensity");
    ASSERT_TRUE(scene.environment);
    EXPECT_EQ(scene.environment->width, 4);
    EXPECT_EQ(scene.environment->height, 2);
    expectNear(scene.environment->radiance, vec3(4), 0.0f, "scale");
    EXPECT_FLOAT_EQ(scene.environment->rgb[5], 0.25f);
    Scene constant =
        loadScene(dir.write("c.yaml", "light: {type: Environment, colour: [1, 2, 3]}\n"));
    ASSERT_TRUE(constant.environment);
    EXPECT_TRUE(constant.environment->path.empty());
    expectNear(constant.environment->radiance, vec3(1, 2, 3), 0.0f, "colour");
}

// The hit-sort key holds 12 bits of shader and 20 of object: the loader caps both, a light
// counting one of each, and names the first element beyond the cap.
TEST(Loader, ShaderAndObjectCountsStayWithinTheHitKey) {
    TempDir dir;
    std::string shaders = "shaders:\n";
    for (int i = 0; i < kMaxShaders - 1; ++i)
        shaders += "  - {type: Lambert}\n";
    const std::string light = "lights:\n  - {type: Quad}\n  - {type: Quad}\n";
    // kMaxShaders - 1 shaders and one light fit; a second light does not.
    const std::string full = dir.write("full.yaml", shaders + "lights:\n  - {type: Quad}\n");
    EXPECT_EQ(loadScene(full).shaders.size(), size_t(kMaxShaders));
    const std::string over = dir.write("over.yaml", shaders + light);
    try {
        loadScene(over);
        ADD_FAILURE() << "loaded " << kMaxShaders + 1 << " shaders";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.line(), kMaxShaders + 3) << e.what();
        EXPECT_NE(std::string(e.what()).find("more than 4095 shaders"), std::string::npos)
            << e.what();
    }
    const std::string lightsFirst = dir.write("first.yaml", light + shaders);
    try {
        loadScene(lightsFirst);
        ADD_FAILURE() << "loaded " << kMaxShaders + 1 << " shaders";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.line(), 3 + kMaxShaders) << e.what(); // the last shader
    }
}

// ---- errors, through the real binary ----------------------------------------------------------

struct ErrorCase {
    const char* name;
    const char* scene;   // written to scene.yaml next to tri.obj and bad.obj
    int line;            // the line the message must name
    const char* message; // a part of the message; with inObj, the OBJ file the error must name
    bool inObj = false;  // the error is in an OBJ file, not in the scene file
};

void PrintTo(const ErrorCase& c, std::ostream* os) {
    *os << c.name;
}

class LoaderError : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(LoaderError, ExitsTwoNamingFileAndLine) {
    const ErrorCase& c = GetParam();
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    dir.write("bad.obj", "# one vertex is not a number\nv 0 0 0\nv 1 0 0\nv nan 0 0\nf 1 2 3\n");
    dir.write("bad_inf.obj", "v 0 0 0\nv 0 inf 0\nv 1 0 0\nf 1 2 3\n");
    dir.write("big.obj", "v 0 0 0\nv 1e15 0 0\nv 0 1e15 0\nf 1 2 3\n");
    writeTexture(dir.file("textures/ok.tx"), 0.5f);
    writeImage(dir.file("negative.exr"), ImageRGB{2, 1, {0.5f, 0.5f, 0.5f, 0.5f, -1.0f, 0.5f}});
    const std::string scenePath = dir.write("scene.yaml", c.scene);
    const std::string output = dir.file("out.exr");
    CommandResult r = runSpillway("render " + scenePath + " -o " + output + " --quiet");

    EXPECT_EQ(r.status, 2) << r.output;
    const std::string file = c.inObj ? dir.file(c.message) : scenePath;
    const std::string where = file + ":" + std::to_string(c.line) + ":";
    EXPECT_EQ(r.output.rfind(where, 0), 0u)
        << "expected output to start with '" << where << "', got: " << r.output;
    if (!c.inObj) {
        EXPECT_NE(r.output.find(c.message, where.size()), std::string::npos) << r.output;
    }
    EXPECT_FALSE(fs::exists(output)) << "an image was written despite the error";
}

const ErrorCase kErrorCases[] = {
    {"UnknownTopLevelKey", "image: {width: 8, height: 8}\nmaterials: {type: Lambert}\n", 2,
     "materials"},
    {"UnknownCameraKey", "camera:\n  type: PinHole\n  zoom: 3\n", 3, "zoom"},
    {"UnknownKeyInObject",
     "shader: {type: Lambert}\nobject:\n  filename: tri.obj\n  colour: [1, 0, 0]\n", 4, "colour"},
    {"WidthNotAnInteger", "image:\n  height: 8\n  width: abc\n", 3, "width"},
    {"WidthNotWhole", "image:\n  width: 8.5\n", 2, "width"},
    {"StringWhereListExpected", "camera:\n  type: PinHole\n  translation: far away\n", 3,
     "translation"},
    {"ListWithTooFewNumbers", "light:\n  type: Quad\n  colour: [1, 1]\n", 3, "colour"},
    {"MapWhereNumberExpected", "shader:\n  type: Lambert\n  reflectance: {a: 1}\n", 3,
     "reflectance"},
    {"NegativeWidth", "settings: {max depth: 4}\nimage:\n  width: -5\n", 3, "width"},
    {"ZeroHeight", "image: {width: 8,\n  height: 0}\n", 2, "height"},
    {"NegativeLightScale", "light:\n  type: Quad\n  scale: [1, -2]\n", 3, "scale"},
    {"NegativeLightIntensity", "light:\n  type: Quad\n  intensity: -1\n", 3, "intensity"},
    {"TextureCacheBelowOneMiB", "settings:\n  texture cache: 0.5\n", 2, "texture cache"},
    {"ReflectanceAboveOne", "shader:\n  type: Lambert\n  reflectance: 1.5\n", 3, "reflectance"},
    {"NegativeMaxDepth", "settings:\n  min depth: 2\n  max depth: -1\n", 3, "max depth"},
    {"NanIntensity", "light:\n  type: Quad\n  intensity: .nan\n", 3, "intensity"},
    {"InfTranslation", "camera:\n  translation: [0, .inf, 0]\n", 2, "translation"},
    {"NegativeInfFocalLength", "camera:\n  focal length: -.inf\n", 2, "focal length"},
    {"NanInObjectScale",
     "shader: {type: Lambert}\nobject:\n  filename: tri.obj\n  scale: [1, .NaN, 1]\n", 4, "scale"},
    {"ShaderIndexMissingFlow",
     "shader: {type: Lambert}\nobject: {type: Polygon, filename: tri.obj, shader: 1}\n", 2,
     "shader 1"},
    {"ShaderIndexMissingBlock",
     "shader: {type: Lambert}\nobject:\n  type: Polygon\n  filename: tri.obj\n  shader: 3\n", 5,
     "shader 3"},
    {"NoShadersAtAll", "object: {type: Polygon, filename: tri.obj}\n", 1, "shader 0"},
    {"MissingObjFile",
     "shader: {type: Lambert}\nobject:\n  type: Polygon\n  filename: nowhere.obj\n", 4,
     "nowhere.obj"},
    {"MissingTextureFile",
     "shader:\n  type: Lambert\n  texture:\n    type: Layered\n    upper: {type: Standard, string: "
     "textures/ok.tx}\n"
     "    lower:\n      type: Standard\n      string: textures/none.tx\n    mask: {type: "
     "Constant}\n",
     8, "none.tx"},
    {"ConductorAlphaAboveOne",
     "image: {width: 4, height: 4}\nshader:\n  type: Conductor\n  alpha: 1.5\n", 4, "alpha"},
    {"ConductorColourAboveOne", "shader:\n  type: Conductor\n  colour: [1, 1.2, 1]\n", 3, "colour"},
    {"ConductorTakesNoIor", "shader:\n  type: Conductor\n  ior: 1.5\n", 3, "ior"},
    {"IorBelowRange", "shader:\n  type: Dielectric\n  ior: 1.0\n", 3, "ior"},
    {"IorAboveRange", "shader:\n  type: Dielectric\n  ior: 10.5\n", 3, "ior"},
    {"DielectricIorBelowOne", "shaders:\n  - {type: Lambert}\n  - {type: Dielectric, ior: 0.8}\n",
     3, "ior"},
    {"DielectricNegativeAlpha", "shader:\n  type: Dielectric\n  alpha: -0.1\n", 3, "alpha"},
    {"DielectricTakesNoMetallic", "shader:\n  type: Dielectric\n  metallic: 1\n", 3, "metallic"},
    {"DielectricNegativeAbsorption", "shader:\n  type: Dielectric\n  absorption: [1, -1, 1]\n", 3,
     "absorption"},
    {"CoatAboveOne", "shader:\n  type: CoatedMetallicRoughness\n  coat: 1.5\n", 3, "coat"},
    {"TransmissionBelowZero",
     "shader:\n  type: TransmissiveMetallicRoughness\n  transmission: -0.5\n", 3, "transmission"},
    {"SheenColourAboveOne",
     "shader:\n  type: SheenMetallicRoughness\n  sheen colour: [1, 1.5, 1]\n", 3, "sheen colour"},
    {"SpecularAboveOne", "shader:\n  type: MetallicRoughness\n  specular: 1.5\n", 3, "specular"},
    {"SpecularColourNegative",
     "shader:\n  type: MetallicRoughness\n  specular colour: [1, -1, 1]\n", 3, "specular colour"},
    {"PointLightWithoutPosition", "light: {type: Quad}\nlight:\n  type: Point\n  intensity: 2\n", 3,
     "needs a position"},
    {"PointLightFarAway", "light: {type: Point, position: [0, 1e16, 0]}\n", 1, "1e16 units"},
    {"EnvironmentColourAndImage",
     "lights:\n  - {type: Environment, colour: [1, 1, 1], string: sky.exr}\n", 2, "not both"},
    {"EnvironmentImageMissing", "light: {type: Environment, string: none.exr}\n", 1,
     "does not exist"},
    {"EnvironmentNegativeRadiance", "light: {type: Environment, string: negative.exr}\n", 1,
     "radiance -1 at texel (1, 0)"},
    {"SecondEnvironment", "lights:\n  - {type: Environment}\n  - {type: Environment}\n", 3,
     "second Environment"},
    {"UnknownLightType", "light: {type: Area}\n", 1,
     "Quad, Point, Environment, Directional or Spot"},
    {"UnknownShaderType", "shader:\n  type: Phong\n", 2, "Phong"},
    {"YamlSyntaxError", "image:\n  width: 8\n  height: 8: 9\n", 3, "YAML"},
    {"ImageTwice", "image: {width: 8}\ncamera: {fov: 40}\nimage: {height: 8}\n", 3, "image"},
    {"ObjectsNotAList", "shader: {type: Lambert}\nobjects: {filename: tri.obj}\n", 2, "list"},
    {"ObjNanVertex", "shader: {type: Lambert}\nobject: {filename: bad.obj}\n", 4, "bad.obj", true},
    {"ObjInfVertex", "shader: {type: Lambert}\nobject: {filename: bad_inf.obj}\n", 2, "bad_inf.obj",
     true},
    {"ObjVertexInfiniteAfterTransform",
     "shader: {type: Lambert}\nobject: {filename: big.obj, scale: 1e30}\n", 2, "big.obj", true},
    {"ObjTriangleTooLargeForFloat", "shader: {type: Lambert}\nobject:\n  filename: big.obj\n", 3,
     "too large"},
    {"QuadLightWithoutAreaInFloat", "light:\n  type: Quad\n  scale: [1e-30, 1e-30]\n", 2,
     "no area"},
    {"MoreSamplesPerPixelThan2To32", "image:\n  sample base: 256\n  iterations: 16777216\n", 2,
     "2^32"},
    {"AbsurdImageSize", "image:\n  width: 32768\n  height: 32768\n", 2, "larger than"},
    {"AbsurdWidth", "image:\n  width: 1000000000\n", 2, "width"},
};

INSTANTIATE_TEST_SUITE_P(Loader, LoaderError, ::testing::ValuesIn(kErrorCases),
                         [](const ::testing::TestParamInfo<ErrorCase>& info) {
                             return std::string(info.param.name);
                         });

} // namespace
} // namespace spw::test
