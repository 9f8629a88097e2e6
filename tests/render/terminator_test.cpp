// The shadow terminator of smooth-shaded meshes (shared/offset.h's shadowLift, after Hanika
// 2021): a low-poly sphere with vertex normals, lit from the side, is shaded like the smooth
// sphere it stands for, its terminator a curve and not the steps of its facets, on every
// backend and at every scale.
#include "host/loaders/scene_loader.h"
#include "host/scene_view/hit_setup.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include "shared/offset.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace spw::test {
namespace {

// A UV sphere of radius 1 about the origin: `segments` around, segments / 2 rings, each vertex's
// normal the sphere's there.
json uvSphere(GltfBuilder& b, int segments) {
    const int rings = segments / 2;
    std::vector<float> pos, nor;
    std::vector<uint32_t> idx;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s <= segments; ++s) {
            const double theta = M_PI * r / rings, phi = 2.0 * M_PI * s / segments;
            const float x = float(std::sin(theta) * std::cos(phi)), y = float(std::cos(theta)),
                        z = float(std::sin(theta) * std::sin(phi));
            pos.insert(pos.end(), {x, y, z});
            nor.insert(nor.end(), {x, y, z});
        }
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const uint32_t a = uint32_t(r * (segments + 1) + s), c = a + uint32_t(segments) + 1;
            // Counter-clockwise seen from outside; the poles' zero-area triangles are dropped.
            idx.insert(idx.end(), {a, a + 1, c, a + 1, c + 1, c});
        }
    return {{"attributes",
             {{"POSITION", b.accessor<float>(pos, 5126, "VEC3")},
              {"NORMAL", b.accessor<float>(nor, 5126, "VEC3")}}},
            {"indices", b.accessor<uint32_t>(idx, 5125, "SCALAR")},
            {"material", 0}};
}

// The sphere, `segments` around, scaled by `scale` and moved `away` along x, seen from +z
// filling a 48 x 48 image, lit only by a sun travelling along -x: its terminator runs down the
// middle of the image. With `panel`, lit instead by an emissive square far off along the sun's
// way (triangles: the cpu backend's SIMD shading takes them). Direct light only (one bounce),
// 4 spp.
std::vector<float> litSphere(const TempDir& dir, int segments, double scale, double away,
                             BackendKind backend, bool panel = false) {
    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.8f), 0.0f, 1.0f)});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({{{"type", "directional"}, {"intensity", 683.0}}});
    b.doc["cameras"] = json::array(
        {{{"type", "perspective"},
          {"perspective", {{"yfov", 0.5}, {"aspectRatio", 1.0}, {"znear", 0.01 * scale}}}}});
    // glTF's lights shine along their -Z: turned to travel along (-1, -0.15, -0.1), across the
    // facets' edges rather than along them.
    const vec3 from(0, 0, -1), to = glm::normalize(vec3(-1.0f, -0.15f, -0.1f));
    const vec4 sunTurn = glm::normalize(vec4(glm::cross(from, to), 1.0f + glm::dot(from, to)));
    std::vector<int> nodes = {b.node({{"mesh", b.mesh(uvSphere(b, segments))},
                                      {"scale", {scale, scale, scale}},
                                      {"translation", {away, 0.0, 0.0}}}),
                              b.node({{"camera", 0}, {"translation", {away, 0.0, 4.5 * scale}}})};
    if (panel) {
        // A 4 x 4 square 40 away, its front (+Z) turned to face along the sun's way.
        b.doc["materials"].push_back(material(vec3(0.0f), 0.0f, 1.0f, vec3(1.0f)));
        const vec3 up(0, 0, 1);
        const vec4 turn = glm::normalize(vec4(glm::cross(up, to), 1.0f + glm::dot(up, to)));
        const vec3 centre = -40.0f * to;
        // The unit quaternion `turn` applied to the square's centre offset (2, 2, 0).
        const vec3 q(turn.x, turn.y, turn.z), v(2.0f, 2.0f, 0.0f);
        const vec3 turned =
            v + 2.0f * turn.w * glm::cross(q, v) + 2.0f * glm::cross(q, glm::cross(q, v));
        const vec3 corner = centre - turned;
        nodes.push_back(b.node(
            {{"mesh", b.mesh(b.quad(1))},
             {"rotation", {turn.x, turn.y, turn.z, turn.w}},
             {"scale", {4.0 * scale, 4.0 * scale, 4.0 * scale}},
             {"translation", {away + corner.x * scale, corner.y * scale, corner.z * scale}}}));
        b.doc.erase("extensions");
        b.doc.erase("extensionsUsed");
    } else {
        nodes.push_back(b.node({{"rotation", {sunTurn.x, sunTurn.y, sunTurn.z, sunTurn.w}},
                                {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}));
    }
    b.scene(nodes);
    Scene scene = loadScene(b.embedded(dir, "sphere.gltf"));
    // The square alone lights the sphere, dim as it is from 40 away (where a file's emitters
    // are this dim, the loader adds a white environment: --environment 0,0,0 takes it out).
    if (panel) scene.environment.reset();
    scene.image.width = scene.image.height = 48;
    scene.settings.maxDepth = 1;
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = 4;
    return render(scene, cfg)->film->image();
}

// Pixels well inside the sphere's outline, within 0.8 of its radius (the polygon and the circle
// agree there), where the smooth sphere is lit (above 5 % of its brightest).
bool inside(int x, int y) {
    // The sphere's radius in pixels: 24 / (4.5 tan(0.25)) / sqrt(1 - 1 / 4.5^2).
    return std::hypot(x + 0.5 - 24.0, y + 0.5 - 24.0) < 0.8 * 21.7;
}

// The least and the greatest ratio of `coarse` to `fine` over the pixels inside() that `fine`
// lights (a lit half disc: at least 300 of them, checked here). Without the lift, the coarse
// sphere's facets next to the terminator face away from the sun while their vertex normals do not,
// and come out black: a least ratio of 0.
std::pair<double, double> ratioRange(const std::vector<float>& coarse,
                                     const std::vector<float>& fine) {
    const float brightest = *std::max_element(fine.begin(), fine.end());
    double lo = HUGE_VAL, hi = 0.0;
    int lit = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x) {
            const size_t i = size_t(y * 48 + x) * 3 + 1;
            if (!inside(x, y) || !(fine[i] > 0.05f * brightest)) continue;
            lo = std::min(lo, double(coarse[i] / fine[i]));
            hi = std::max(hi, double(coarse[i] / fine[i]));
            ++lit;
        }
    EXPECT_GE(lit, 300);
    return {lo, hi};
}

// A 16-segment sphere against a 256-segment one, pixel by pixel where the smooth sphere is lit:
// without the lift, three columns along the terminator were black (a least ratio of 0, 26
// pixels under half); with it, 0.96 to 1.04 (the facets' interpolated normals are not quite the
// sphere's). On every backend; tiny, huge and far from the origin the same, as the lift scales
// with the mesh.
TEST(Terminator, ALowPolySphereIsShadedAsTheSmoothSphere) {
    TempDir dir;
    const std::vector<float> fine = litSphere(dir, 256, 1.0, 0.0, BackendKind::Reference);
    auto expectSmooth = [&](const std::vector<float>& coarse) {
        const auto [lo, hi] = ratioRange(coarse, fine);
        EXPECT_GT(lo, 0.9);
        EXPECT_LT(hi, 1.1);
    };
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        expectSmooth(litSphere(dir, 16, 1.0, 0.0, backend));
    }
    for (const auto& [scale, away] : {std::pair{1e-4, 0.0}, {1e4, 0.0}, {1.0, 1e5}}) {
        SCOPED_TRACE(std::to_string(scale) + " at " + std::to_string(away));
        expectSmooth(litSphere(dir, 16, scale, away, BackendKind::Cpu));
    }
    // Lit by a distant emissive square, through the SIMD shading's twin of the same arithmetic.
    const std::vector<float> finePanel =
        litSphere(dir, 256, 1.0, 0.0, BackendKind::Reference, true);
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu}) {
        SCOPED_TRACE(backendName(backend) + std::string(", the square"));
        const auto [lo, hi] = ratioRange(litSphere(dir, 16, 1.0, 0.0, backend, true), finePanel);
        EXPECT_GT(lo, 0.9);
        EXPECT_LT(hi, 1.1);
    }
}

// The lift itself: 0 on a flat mesh and at a vertex, the height of the tangent planes'
// interpolation above the triangle elsewhere; its sign follows the vertex normals' side.
TEST(Terminator, TheLiftIsTheSmoothSurfacesHeightAboveTheTriangle) {
    Mesh m;
    m.positions = {vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0)};
    m.triangles = {uvec3(0, 1, 2)};
    const vec3 ng(0, 0, 1);
    const vec3 centre(1.0f / 3.0f, 1.0f / 3.0f, 0.0f);
    EXPECT_EQ(HitSetup::smoothLift(m, m.triangles[0], 1.0f / 3, 1.0f / 3, centre, ng), 0.0f);
    m.normals = {ng, ng, ng};
    EXPECT_EQ(HitSetup::smoothLift(m, m.triangles[0], 1.0f / 3, 1.0f / 3, centre, ng), 0.0f);
    // Normals leaning out from the centre, as on a sphere: each plane through its vertex tilted
    // away lies above the centre by dot(v - centre, n).
    const float lean = 0.3f;
    for (int i = 0; i < 3; ++i)
        m.normals[size_t(i)] = glm::normalize(vec3(m.positions[size_t(i)] - centre) * lean + ng);
    float expected = 0.0f;
    for (int i = 0; i < 3; ++i) {
        const vec3 n = m.normals[size_t(i)];
        expected += glm::dot(m.positions[size_t(i)] - centre, n) * n.z / 3.0f;
    }
    const float lift = HitSetup::smoothLift(m, m.triangles[0], 1.0f / 3, 1.0f / 3, centre, ng);
    EXPECT_GT(lift, 0.0f);
    EXPECT_NEAR(lift, expected, 1e-6f);
    EXPECT_EQ(HitSetup::smoothLift(m, m.triangles[0], 0.0f, 0.0f, m.positions[0], ng), 0.0f);
    // The triangle wound the other way (its geometric normal down), the vertex normals as
    // they were: the smooth surface lies on the other side of ng.
    EXPECT_NEAR(HitSetup::smoothLift(m, m.triangles[0], 1.0f / 3, 1.0f / 3, centre, -ng), -expected,
                1e-6f);
    // Normals leaning in, a concave surface: the triangle is above every tangent plane, no lift.
    for (vec3& n : m.normals)
        n = glm::normalize(vec3(-n.x, -n.y, n.z));
    EXPECT_EQ(HitSetup::smoothLift(m, m.triangles[0], 1.0f / 3, 1.0f / 3, centre, ng), 0.0f);
}

// A shadow ray takes the lift only toward the side the smooth surface lies on, at most a quarter
// of the way to the light, never where there is no way at all.
TEST(Terminator, AShadowRayIsLiftedOnlyTowardTheSmoothSurface) {
    const vec3 ng(0, 0, 1);
    EXPECT_EQ(shadowLift(ng, 0.1f, vec3(0, 0.6f, 0.8f), 100.0f), 0.1f);
    EXPECT_EQ(shadowLift(ng, 0.1f, vec3(0, 0.6f, -0.8f), 100.0f), 0.0f);
    EXPECT_EQ(shadowLift(ng, -0.1f, vec3(0, 0.6f, -0.8f), 100.0f), 0.1f);
    EXPECT_EQ(shadowLift(ng, 0.1f, vec3(0, 0.6f, 0.8f), 0.2f), 0.05f);
    EXPECT_EQ(shadowLift(ng, 0.1f, vec3(0, 0.6f, 0.8f), -1.0f), 0.0f);
    EXPECT_EQ(shadowLift(ng, 0.0f, vec3(0, 0.6f, 0.8f), 100.0f), 0.0f);
}

} // namespace
} // namespace spw::test
