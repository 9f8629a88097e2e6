#include "fuzz_targets.h"

#include "host/image/image_io.h"
#include "host/loaders/obj_mesh.h"
#include "host/loaders/scene_loader.h"
#include "host/render/checkpoint.h"
#include "host/render/render.h"
#include "host/scene/scene.h"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace spw::fuzz {
namespace {

namespace fs = std::filesystem;

// One private folder for the process, removed at exit.
class Folder {
  public:
    Folder() {
        std::string templ = (fs::temp_directory_path() / "spillway-fuzz-XXXXXX").string();
        if (!::mkdtemp(templ.data())) std::abort();
        path_ = templ;
        writeImage(path_ + "/tex.png", {4, 4, std::vector<float>(4 * 4 * 3, 0.5f)});
    }
    ~Folder() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string write(const std::string& name, const char* data, std::size_t size) const {
        const std::string p = path_ + "/" + name;
        std::ofstream(p, std::ios::binary | std::ios::trunc).write(data, std::streamsize(size));
        return p;
    }

  private:
    std::string path_;
};

const Folder& folder() {
    static Folder f;
    return f;
}

// A loaded scene rendered by the reference backend at 4 x 4 pixels, 1 sample, depth <= 3.
void renderSmall(Scene s) {
    s.image.width = std::min(s.image.width, 4);
    s.image.height = std::min(s.image.height, 4);
    s.image.sampleBase = 1;
    s.image.iterations = 1;
    s.settings.maxDepth = std::min(s.settings.maxDepth, 3);
    RenderConfig config;
    config.backend = BackendKind::Reference;
    config.threads = 1;
    render(s, config);
}

template <class Body> Outcome guarded(Body body, std::string* detail) {
    try {
        body();
        return Outcome::Accepted;
    } catch (const SceneError&) {
        return Outcome::Rejected;
    } catch (const std::exception& e) {
        if (detail) *detail = e.what();
        return Outcome::Unexpected;
    }
}

} // namespace

Outcome scene(const std::uint8_t* data, std::size_t size, std::string* detail) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const std::string marker = "#@obj\n";
    const size_t at = text.find(marker);
    const std::string yaml = text.substr(0, at);
    const std::string objText =
        at == std::string::npos ? std::string() : text.substr(at + marker.size());
    folder().write("mesh.obj", objText.data(), objText.size());
    const std::string path = folder().write("scene.yaml", yaml.data(), yaml.size());
    return guarded([&] { renderSmall(loadScene(path)); }, detail);
}

Outcome gltf(const std::uint8_t* data, std::size_t size, std::string* detail) {
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const std::string path = folder().write(binary ? "model.glb" : "model.gltf",
                                            reinterpret_cast<const char*>(data), size);
    return guarded([&] { renderSmall(loadScene(path)); }, detail);
}

Outcome obj(const std::uint8_t* data, std::size_t size, std::string* detail) {
    const std::string path = folder().write("alone.obj", reinterpret_cast<const char*>(data), size);
    return guarded([&] { loadObjMesh(path, glm::dmat4(1.0), glm::dvec3(0.0), "fuzz.yaml", 1); },
                   detail);
}

Outcome checkpoint(const std::uint8_t* data, std::size_t size, std::string* detail) {
    const std::string path =
        folder().write("checkpoint.exr", reinterpret_cast<const char*>(data), size);
    try {
        const Checkpoint c = readCheckpoint(path);
        try {
            mergePartials({{"a.exr", c}, {"b.exr", c}});
        } catch (const std::invalid_argument&) {
            // the overlap (or a gap) is reported, as it should be
        }
        return Outcome::Accepted;
    } catch (const std::runtime_error&) {
        return Outcome::Rejected;
    } catch (const std::invalid_argument&) {
        return Outcome::Rejected;
    } catch (const std::exception& e) {
        if (detail) *detail = e.what();
        return Outcome::Unexpected;
    }
}

} // namespace spw::fuzz
