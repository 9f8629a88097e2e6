// The scene: everything SCENE_FORMAT.md describes, resolved to world space and immutable once
// loaded. Backends read it; nothing writes it after loadScene() returns.
#pragma once

#include "shared/types.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace spw {

// A scene error: where in which file, and what is wrong. The CLI prints "file:line: message"
// and exits 2.
class SceneError : public std::runtime_error {
  public:
    SceneError(std::string file, int line, const std::string& message)
        : std::runtime_error(file + ":" + std::to_string(line) + ": " + message),
          file_(std::move(file)), line_(line) {}
    const std::string& file() const { return file_; }
    int line() const { return line_; }

  private:
    std::string file_;
    int line_;
};

struct ImageSettings {
    int width = 512;
    int height = 512;
    int sampleBase = 1; // n: n*n samples per pixel per iteration
    int iterations = 1;
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
    std::uint32_t seed = 0;
};

enum class CameraType { PinHole, ThinLens };

struct Camera {
    CameraType type = CameraType::PinHole;
    mat4 cameraToWorld{1.0f}; // looks along local -Z, +Y up
    float focalLength = 35.0f; // mm
    float filmWidth = 35.0f;   // mm
    std::optional<float> fovDegrees; // horizontal; overrides the focal length
    float apertureRadius = 0.0f;
    float focalDistance = 1.0f;
    // tan(horizontal half angle)
    float tanHalfFovX() const;
};

enum class FilterType { Box, Tent, Gaussian };
struct Filter {
    FilterType type = FilterType::Box;
    float radius = 0.5f; // pixels; Box always covers its own pixel only
};

enum class SamplerType { Independent, Grid, Stratified };

enum class TextureType { Constant, Standard, Layered };
struct Texture {
    TextureType type = TextureType::Constant;
    vec3 colour{1.0f};
    std::string path; // Standard: absolute path of the image
    int upper = -1, lower = -1, mask = -1; // Layered: indices into Scene::textures
};

struct Shader {
    ShaderParams params{};
    int texture = -1; // root of the texture tree, or -1
    std::string typeName;
    int line = 0;
};

// A triangle mesh in world space. Vertex attributes are per vertex; normals and uvs are empty
// when the OBJ has none.
struct Mesh {
    std::vector<vec3> positions;
    std::vector<vec3> normals;
    std::vector<vec2> uvs;
    std::vector<uvec3> triangles;
    int shader = 0;
    std::string name; // the file, or "quad light N"
    int droppedTriangles = 0; // zero-area triangles left out when loading
};

struct Scene {
    std::string file;
    ImageSettings image;
    Settings settings;
    Camera camera;
    Filter filter;
    SamplerType sampler = SamplerType::Independent;
    std::vector<Shader> shaders;   // scene shaders first, then one emissive Null per quad light
    std::vector<Texture> textures;
    std::vector<Mesh> meshes;      // objects first, then the quad lights' geometry
    int objectCount = 0;
    int quadLightCount = 0;

    bool usesTextures() const;
};

// Parses and validates a scene file. Throws SceneError (file:line: message) on any problem.
Scene loadScene(const std::string& path);

} // namespace spw
