// A surface model is complete only with every piece docs/adding-a-surface-model.md lists: this
// test walks the registry (host/scene/surface_models.h) and fails for a registered model that
// lacks its shared header (dispatched from bsdf.h), its BSDF test, or a scene name the loader
// accepts. Its kernel and the kModel* count are checked in tests/vk (SurfaceModels.*).
#include "host/scene/scene.h"
#include "host/scene/surface_models.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace spw::test {
namespace {

TEST(SurfaceModels, EveryRegisteredModelHasItsHeaderItsTestAndItsSceneName) {
    const std::string bsdf = readFile(sourceDir() + "/shaders/shared/bsdf.h");
    ASSERT_FALSE(bsdf.empty());
    TempDir dir;
    const std::string box = sourceDir() + "/scenes/cornell-box/";
    for (size_t i = 0; i < kSurfaceModelCount; ++i) {
        const SurfaceModelInfo& m = kSurfaceModels[i];
        const std::string stem = m.kernel, name = m.name;
        EXPECT_TRUE(std::filesystem::exists(sourceDir() + "/shaders/" + stem + ".comp"))
            << name << ": no shaders/" << stem << ".comp";
        // The loader takes the registry's name and gives the registry's model constant.
        const Scene scene = loadScene(dir.write(
            stem + ".yaml", "image: {width: 4, height: 4}\n"
                            "camera: {type: PinHole, look at: {eye: [278, 273, -800], target: "
                            "[278, 273, 0]}, fov: 39.3}\n"
                            "shaders:\n  - {type: " +
                                name + "}\nobjects:\n  - {filename: " + box + "white.obj, shader: 0}\n"));
        ASSERT_EQ(scene.shaders.size(), 1u) << name;
        EXPECT_EQ(scene.shaders[0].params.model, m.model) << name;
        if (m.model == kModelNull) continue; // no response: no BSDF of its own to test
        EXPECT_TRUE(std::filesystem::exists(sourceDir() + "/shaders/shared/" + stem + ".h"))
            << name << ": no shaders/shared/" << stem << ".h";
        EXPECT_NE(bsdf.find("#include \"" + stem + ".h\""), std::string::npos)
            << name << ": bsdf.h does not include " << stem << ".h";
        const std::string test = readFile(sourceDir() + "/tests/bsdf/" + stem + "_test.cpp");
        EXPECT_NE(test.find("TEST(" + name + ","), std::string::npos)
            << name << ": no TEST(" << name << ", ...) in tests/bsdf/" << stem << "_test.cpp";
    }
}

} // namespace
} // namespace spw::test
