#include "host/scene/textures.h"

#include "host/image/image_io.h"

#include <OpenImageIO/texture.h>

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>

namespace spw {

struct TextureResolver::Impl {
    OIIO::TextureSystem* system = nullptr;
    struct Image {
        OIIO::TextureSystem::TextureHandle* handle = nullptr;
        bool srgb = false;
        int channels = 3;
    };
    std::vector<Image> images; // parallel to Scene::textures (only Standard entries are used)
    // The first failed lookup, reported after the iteration (a lookup cannot throw mid-batch).
    std::atomic<bool> failed{false};
    std::mutex errorMutex;
    int failedTexture = -1;
    std::string error;
    mutable std::atomic<std::uint64_t> peakCacheBytes{0};
    bool filtered = true;
    // One lookup, with the calling thread's OpenImageIO state and the options fetched by the
    // caller (once per run of lookups).
    vec3 lookup(int index, vec2 uv, float footprint, OIIO::TextureSystem::Perthread* thread,
                OIIO::TextureOpt& opt);
    ~Impl() {
        if (system) OIIO::TextureSystem::destroy(system);
    }
};

namespace {

// Children-first order of the nodes reachable from `root`, each once.
void visit(const Scene& scene, int t, std::vector<int>& slotOf, std::vector<int>& order) {
    if (slotOf[size_t(t)] >= 0) return;
    const Texture& tex = scene.textures[size_t(t)];
    if (tex.type == TextureType::Layered)
        for (int child : {tex.upper, tex.lower, tex.mask})
            visit(scene, child, slotOf, order);
    slotOf[size_t(t)] = int(order.size());
    order.push_back(t);
}

} // namespace

TextureResolver::TextureResolver(const Scene& scene, double cacheMiB, bool filtered)
    : scene_(scene) {
    programs_.resize(scene.textures.size());
    for (const Shader& sh : scene.shaders) {
        if (sh.texture < 0 || !programs_[size_t(sh.texture)].empty()) continue;
        // The loader bounds the depth (kMaxTextureDepth), so this recursion is bounded too.
        std::vector<int> slotOf(scene.textures.size(), -1), order;
        visit(scene, sh.texture, slotOf, order);
        std::vector<Op>& program = programs_[size_t(sh.texture)];
        for (int t : order) {
            const Texture& tex = scene.textures[size_t(t)];
            Op op{tex.type, t, -1, -1, -1};
            if (tex.type == TextureType::Layered)
                op.upper = slotOf[size_t(tex.upper)], op.lower = slotOf[size_t(tex.lower)],
                op.mask = slotOf[size_t(tex.mask)];
            program.push_back(op);
        }
    }
    int standard = 0;
    for (const Texture& t : scene.textures)
        standard += t.type == TextureType::Standard;
    if (standard == 0) return;
    impl_ = std::make_unique<Impl>();
    impl_->filtered = filtered;
    impl_->system = OIIO::TextureSystem::create(false);
    impl_->system->attribute("max_memory_MB", float(cacheMiB));
    // Keep every texture file open if the process may (OpenImageIO's default of 100 made the
    // production scene's 448 files re-open 1400 times a render), half the descriptors at most.
    rlimit files{};
    const rlim_t allowed = getrlimit(RLIMIT_NOFILE, &files) == 0 ? files.rlim_cur / 2 : 100;
    impl_->system->attribute(
        "max_open_files",
        int(std::clamp<rlim_t>(rlim_t(standard) + 16, 100, std::max<rlim_t>(allowed, 100))));
    impl_->images.resize(scene.textures.size());
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        if (t.type != TextureType::Standard) continue;
        Impl::Image& img = impl_->images[i];
        OIIO::ustring name(t.path);
        img.handle = impl_->system->get_texture_handle(name);
        const OIIO::ImageSpec* spec =
            img.handle ? impl_->system->imagespec(img.handle, nullptr, 0) : nullptr;
        if (!spec)
            throw std::runtime_error("cannot read texture '" + t.path +
                                     "': " + impl_->system->geterror());
        img.channels = spec->nchannels;
        std::string cs = spec->get_string_attribute("oiio:ColorSpace");
        img.srgb = cs == "sRGB" || (cs.empty() && spec->format == OIIO::TypeDesc::UINT8);
    }
}

TextureResolver::~TextureResolver() = default;

namespace {
// Every lookup's options: repeating, bilinear within a level, trilinear across levels.
OIIO::TextureOpt lookupOptions() {
    OIIO::TextureOpt opt;
    opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    opt.mipmode = OIIO::TextureOpt::MipModeTrilinear;
    return opt;
}
} // namespace

vec3 TextureResolver::Impl::lookup(int index, vec2 uv, float footprint,
                                   OIIO::TextureSystem::Perthread* thread, OIIO::TextureOpt& opt) {
    const Image& img = images[size_t(index)];
    if (!filtered) footprint = 0.0f; // zero derivatives: the finest level
    float rgb[4] = {0, 0, 0, 0};
    int nc = std::min(img.channels, 3);
    // OBJ's v grows upwards, image rows downwards. An isotropic footprint: ds/dx = dt/dy.
    if (!system->texture(img.handle, thread, opt, uv.x, 1.0f - uv.y, footprint, 0, 0, footprint, nc,
                         rgb)) {
        if (!failed.exchange(true)) {
            std::lock_guard<std::mutex> lock(errorMutex);
            failedTexture = index;
            error = system->geterror();
        }
        return vec3(0.0f);
    }
    // A one-channel image (a mask) is linearised once, not three times.
    if (nc == 1) return vec3(img.srgb ? srgbToLinear(rgb[0]) : rgb[0]);
    vec3 c(rgb[0], rgb[1], rgb[2]);
    if (img.srgb) c = vec3(srgbToLinear(c.x), srgbToLinear(c.y), srgbToLinear(c.z));
    return c;
}

void TextureResolver::checkErrors() const {
    if (!impl_ || !impl_->failed.load()) return;
    std::lock_guard<std::mutex> lock(impl_->errorMutex);
    const Texture& t = scene_.textures[size_t(impl_->failedTexture)];
    std::string why = impl_->error;
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r'))
        why.pop_back();
    throw SceneError(scene_.file, t.line, "texture file '" + t.path + "' cannot be read: " + why);
}

void TextureResolver::noteCacheUse() const {
    if (!impl_) return;
    long long used = 0;
    impl_->system->getattribute("stat:cache_memory_used", OIIO::TypeDesc::INT64, &used);
    std::uint64_t seen = impl_->peakCacheBytes.load();
    while (std::uint64_t(used) > seen && !impl_->peakCacheBytes.compare_exchange_weak(seen, used)) {
    }
}

TextureStatistics TextureResolver::statistics() const {
    TextureStatistics s;
    if (!impl_) return s;
    noteCacheUse();
    OIIO::TextureSystem& ts = *impl_->system;
    // OpenImageIO answers a counter only when asked in its own type, int64 for some, int for
    // others (and the choice has moved between versions): ask in both.
    auto count = [&](const char* name) {
        long long wide = 0;
        if (ts.getattribute(name, OIIO::TypeDesc::INT64, &wide)) return std::uint64_t(wide);
        int narrow = 0;
        if (ts.getattribute(name, OIIO::TypeDesc::INT, &narrow)) return std::uint64_t(narrow);
        return std::uint64_t(0);
    };
    s.lookups = count("stat:texture_queries");
    s.tilesRead = count("stat:tiles_created");
    s.bytesRead = count("stat:bytes_read");
    s.filesOpened = count("stat:open_files_created");
    const std::uint64_t unique = count("stat:unique_files");
    s.filesReopened = s.filesOpened > unique ? s.filesOpened - unique : 0;
    s.cacheMisses = count("stat:find_tile_cache_misses");
    s.peakCacheBytes = impl_->peakCacheBytes.load();
    return s;
}

vec3 TextureResolver::albedo(const Shader& shader, vec2 uv, float footprint) const {
    vec3 out;
    albedos(shader, 1, &uv, &footprint, &out);
    return out;
}

void TextureResolver::albedos(const Shader& shader, size_t n, const vec2* uv,
                              const float* footprint, vec3* out) const {
    const ShaderParams& p = shader.params;
    if (shader.texture < 0) {
        for (size_t k = 0; k < n; ++k)
            out[k] = p.colour * p.reflectance;
        return;
    }
    const std::vector<Op>& program = programs_[size_t(shader.texture)];
    OIIO::TextureSystem::Perthread* thread = impl_ ? impl_->system->get_perthread_info() : nullptr;
    OIIO::TextureOpt opt = lookupOptions();
    // Every node's values for every hit: nodes x hits, in a per-thread buffer.
    thread_local std::vector<vec3> values;
    if (values.size() < program.size() * n) values.resize(program.size() * n);
    for (size_t i = 0; i < program.size(); ++i) {
        const Op& op = program[i];
        vec3* v = &values[i * n];
        switch (op.type) {
        case TextureType::Constant: {
            const vec3 c = scene_.textures[size_t(op.texture)].colour;
            for (size_t k = 0; k < n; ++k)
                v[k] = c;
            break;
        }
        case TextureType::Standard:
            for (size_t k = 0; k < n; ++k)
                v[k] = impl_->lookup(op.texture, uv[k], footprint[k], thread, opt);
            break;
        case TextureType::Layered: {
            const vec3 *m = &values[size_t(op.mask) * n], *upper = &values[size_t(op.upper) * n],
                       *lower = &values[size_t(op.lower) * n];
            for (size_t k = 0; k < n; ++k)
                v[k] = m[k] * upper[k] + (vec3(1.0f) - m[k]) * lower[k];
            break;
        }
        }
    }
    const vec3* root = &values[(program.size() - 1) * n];
    for (size_t k = 0; k < n; ++k)
        out[k] = root[k] * p.reflectance;
}

} // namespace spw
