// An emitter kind is one registry line (shaders/shared/emitter_kinds.h), its shared header and
// its tests: docs/adding-a-light.md. Everything else is derived from the registry, and this test
// checks both halves: it fails for a registered kind that lacks its header, the header's
// <stem>Sample, or its TEST(<Scene>Light, ...) (in lights_test.cpp, reference_test.cpp or its own
// tests/scene/<stem>_test.cpp), and for a loader that does not take each
// punctual kind by its scene name with exactly the keys its flags name. (That the Vulkan kernels
// agree with the cpu on every kind: VulkanVsCpu.EveryEmitterKindAgreesUpToFloatRounding.)
#include "host/loaders/scene_loader.h"
#include "host/scene/emitter_kinds.h"
#include "host/scene/scene.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace spw::test {
namespace {

TEST(EmitterKinds, EveryRegisteredKindHasItsHeaderItsSampleAndItsTest) {
    const std::string common = readFile(sourceDir() + "/tests/scene/lights_test.cpp") +
                               readFile(sourceDir() + "/tests/render/reference_test.cpp");
    for (const EmitterKindInfo& k : kEmitterKindTable) {
        const std::string stem = k.stem, scene = k.scene;
        // Its tests in those two files, or in a file of its own, tests/scene/<stem>_test.cpp.
        const std::string own = sourceDir() + "/tests/scene/" + stem + "_test.cpp";
        const std::string tests = common + (std::filesystem::exists(own) ? readFile(own) : "");
        const std::string header = sourceDir() + "/shaders/shared/" + stem + ".h";
        ASSERT_TRUE(std::filesystem::exists(header))
            << k.name << ": no shaders/shared/" << stem << ".h";
        EXPECT_NE(readFile(header).find("SHARED_FN LightSample " + stem + "Sample("),
                  std::string::npos)
            << k.name << ": shaders/shared/" << stem << ".h defines no " << stem << "Sample";
        EXPECT_NE(tests.find("TEST(" + scene + "Light,"), std::string::npos)
            << k.name << ": no TEST(" << scene
            << "Light, ...) in tests/scene/lights_test.cpp or tests/scene/" << stem << "_test.cpp";
        EXPECT_EQ(emitterKind(k.kind), &k);
        // A kind the lights make for instances is named by no scene.
        EXPECT_EQ(emitterKindNamed(scene), k.flags & kLightInstanced ? nullptr : &k);
    }
}

TEST(EmitterKinds, TheLoaderTakesEachPunctualKindWithExactlyItsKeys) {
    TempDir dir;
    for (const EmitterKindInfo& k : kEmitterKindTable) {
        if (!k.punctual()) continue;
        const bool positioned = k.flags & kLightTakesPosition;
        const bool directed = k.flags & kLightTakesDirection;
        std::string light = std::string("{type: ") + k.scene + ", intensity: 2";
        if (positioned) light += ", position: [0, 1, 0]";
        if (directed) light += ", direction: [0, -1, 0]";
        const Scene scene = loadScene(
            dir.write("light.yaml", "image: {width: 4, height: 4}\nlight: " + light + "}\n"));
        ASSERT_EQ(scene.punctualLights.size(), 1u) << k.name;
        EXPECT_EQ(scene.punctualLights[0].kind, k.kind) << k.name;
        // A key of the other punctual shape is refused, and so is a missing one.
        const std::string other = positioned ? ", direction: [0, -1, 0]" : ", position: [0, 1, 0]";
        if (!(positioned && directed)) {
            EXPECT_THROW(loadScene(dir.write("bad.yaml", "image: {width: 4, height: 4}\nlight: " +
                                                             light + other + "}\n")),
                         SceneError)
                << k.name;
        }
        EXPECT_THROW(loadScene(dir.write("bad.yaml", std::string("image: {width: 4, height: 4}\n"
                                                                 "light: {type: ") +
                                                         k.scene + "}\n")),
                     SceneError)
            << k.name;
    }
}

} // namespace
} // namespace spw::test
