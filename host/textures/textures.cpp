#include "host/textures/textures.h"

#include "host/image/image_io.h"
#include "host/image/scratch_file.h"
#include "host/textures/embedded_reader.h"
#include "host/textures/texel_reader.h"
#include "host/textures/tiled_copy.h"
#include "host/textures/wide_texels.h"

#include "shared/texture_wrap.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagecache.h>

#include <sys/resource.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <new>
#include <stdexcept>

namespace spw {

namespace {

// x wrapped as `wrap` asks along an axis of n texels (shared/texture_wrap.h); a coordinate that
// is not finite is left for the filter, which reads texel 0 for it.
float wrapAxis(Texture::Wrap wrap, int n, float x) {
    return std::isfinite(x) ? wrapCoordinate(x, wrapMode(wrap), uint(n)) : x;
}

// Texture coordinates (OBJ's: v up) wrapped as a w x h image's texture asks. The clamp interval
// is symmetric, so v's wrap is the same about glTF's v (down) as about OBJ's.
vec2 wrapped(const Texture& t, int w, int h, vec2 uv) {
    return vec2(wrapAxis(t.wrapU, w, uv.x), wrapAxis(t.wrapV, h, uv.y));
}

// The roots of the texture trees shader `sh` reads (its colour's, normal maps', metallic-
// roughness image's, extension maps' and cut-out's), each handed to `f`; -1 where it has none.
template <class F> void forEachTree(const Shader& sh, F&& f) {
    f(sh.texture);
    f(sh.normalTexture);
    f(sh.coatNormalTexture);
    f(sh.metallicRoughnessTexture);
    for (const Shader::ExtensionMap& m : sh.extension)
        f(m.texture);
    f(sh.cutout.enabled ? sh.cutout.texture : -1);
}

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

// Opens a Standard texture's image in the cache (an embedded one through a proxy it keeps):
// its channels, encoding and MIP levels; a large untiled one through its tiled copy
// (tiled_copy.h) unless it is read whole (an emission map). Throws where the image cannot be
// read.
void openImage(const Scene& scene, TextureResolver::Impl& impl, const Texture& t,
               TextureResolver::Impl::Image& img, bool readWhole) {
    // A file must be a regular file before the cache opens it: a FIFO would block the render.
    std::error_code ec;
    if (!t.embedded && !std::filesystem::is_regular_file(t.path, ec))
        throw SceneError(scene.file, t.line, "texture file '" + t.path + "' is not a regular file");
    OIIO::ustring name(t.path);
    if (t.embedded) { // embedded: read through a proxy the cache keeps using
        auto& proxy = impl.proxies.emplace_back(embeddedReader(*t.embedded));
        OIIO::ImageSpec config;
        void* ptr = proxy.get();
        config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &ptr);
        impl.cache->add_file(name, nullptr, &config);
    }
    img.handle = impl.cache->get_image_handle(name);
    const OIIO::ImageSpec* spec =
        img.handle ? impl.cache->imagespec(img.handle, nullptr, 0, 0) : nullptr;
    if (!spec || spec->width < 1 || spec->height < 1)
        throw std::runtime_error("cannot read texture '" + t.path + "': " + impl.cache->geterror());
    // The header's size, before any tile is read.
    if (const std::string why =
            imageSizeProblem(t.path, spec->width, spec->height, kMaxTexturePixels, kMaxTextureSide);
        !why.empty())
        throw SceneError(scene.file, t.line, why);
    img.firstChannel = std::max(t.channel, 0);
    if (spec->nchannels == 2) {
        // Grey and alpha: the grey is every colour channel (one channel read), the alpha the
        // second (Texture::channel 3, the alpha of RGBA).
        img.firstChannel = t.channel == 3 ? 1 : std::min(img.firstChannel, 1);
        img.absent = false;
        img.channels = 1;
    } else {
        img.absent = img.firstChannel >= spec->nchannels;
        img.channels = img.absent ? 1 : spec->nchannels - img.firstChannel;
    }
    img.eightBit = spec->format == OIIO::TypeDesc::UINT8;
    std::string cs = spec->get_string_attribute("oiio:ColorSpace");
    img.srgb = !t.linear && (cs == "sRGB" || (cs.empty() && spec->format == OIIO::TypeDesc::UINT8));
    const int levels = impl.cache->imagespec(img.handle, nullptr, 0, 1) ? 2 : 1;
    img.finest = float(std::max(spec->width, spec->height));
    if (!readWhole && needsTiledCopy(*spec, levels)) {
        // Its copy is made when a lookup first reads it; its levels are the copy's, from the
        // finest down to 1 x 1, each half the one before (tiled_copy.h).
        img.copy = impl.pendingCopy(t, name, *spec, img.srgb);
        for (int w = spec->width, h = spec->height;;
             w = std::max(1, w / 2), h = std::max(1, h / 2)) {
            img.levels.push_back({0, 0, w, h});
            if (w == 1 && h == 1) break;
        }
        return;
    }
    // Its MIP levels, as many as the file has (an image without them is its own only level).
    for (int level = 0; level < int(kMaxLevels); ++level) {
        const OIIO::ImageSpec* ls =
            level == 0 ? spec : impl.cache->imagespec(img.handle, nullptr, 0, level);
        if (!ls || ls->width < 1 || ls->height < 1) break;
        img.levels.push_back({ls->x, ls->y, ls->width, ls->height});
    }
}

} // namespace

std::shared_ptr<TextureResolver::Impl::PendingCopy>
TextureResolver::Impl::pendingCopy(const Texture& t, OIIO::ustring name,
                                   const OIIO::ImageSpec& spec, bool srgb) {
    // One copy per image and encoding; an alpha-only lookup (channel 3) takes either, as the
    // alpha is averaged alike in both.
    const std::string key = name.string() + (srgb ? "\n1" : "\n0");
    auto found = pending.find(key);
    if (found == pending.end() && t.channel == 3)
        found = pending.find(name.string() + (srgb ? "\n0" : "\n1"));
    if (found != pending.end()) return found->second;
    auto copy = std::make_shared<PendingCopy>();
    copy->texture = &t, copy->name = name, copy->spec = spec, copy->srgb = srgb;
    return pending[key] = copy;
}

bool TextureResolver::copiesPending() const {
    return impl_ && impl_->copiesTried.load(std::memory_order_relaxed) < impl_->pending.size();
}

void TextureResolver::Impl::makeCopy(PendingCopy& p) {
    const auto start = std::chrono::steady_clock::now();
    ++copiesTried;
    const Texture& t = *p.texture;
    try {
        OIIO::ImageSpec config;
        std::unique_ptr<OIIO::Filesystem::IOProxy> reader;
        if (t.embedded) { // embedded: read through a proxy of its own, as the cache does
            reader = embeddedReader(*t.embedded);
            void* ptr = reader.get();
            config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &ptr);
        }
        auto copy = std::make_unique<TiledCopy>(t.path, t.embedded ? &config : nullptr, p.spec,
                                                p.srgb, scratch);
        p.handle = cache->get_image_handle(OIIO::ustring(copy->path()));
        if (!p.handle) p.error = "its tiled copy cannot be read: " + cache->geterror();
        // The source, opened for its header alone, is closed again: its pixels are the copy's.
        if (!t.embedded) cache->invalidate(p.name);
        std::lock_guard<std::mutex> lock(copyMutex);
        copies.push_back(std::move(copy));
        tiledCopySeconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    } catch (const TiledCopy::ReadError& e) { // the image's own pixels
        p.handle = nullptr;
        p.error = e.what();
    } catch (const std::bad_alloc&) { // its pixels, and its first coarser level in float
        p.handle = nullptr;
        const std::uint64_t level = std::uint64_t(p.spec.width / 2) *
                                    std::uint64_t(p.spec.height / 2) *
                                    std::uint64_t(p.spec.nchannels) * 4u;
        p.error = outOfMemory(t.path, p.spec.width, p.spec.height, p.spec.image_bytes() + level);
        p.diskFailed = true;            // a runtime failure, as the scratch folder's
    } catch (const std::exception& e) { // the copy's file (a full scratch folder)
        p.handle = nullptr;
        p.error = e.what();
        p.diskFailed = true;
    }
}

void TextureResolver::prepare(const std::vector<bool>& shaders) const {
    if (!impl_ || impl_->pending.empty()) return;
    std::vector<int> images; // the Standard textures the shaders read
    for (size_t s = 0; s < shaders.size() && s < scene_.shaders.size(); ++s) {
        if (!shaders[s]) continue;
        forEachTree(scene_.shaders[s], [&](int root) { standardNodes(root, images); });
    }
    std::vector<Impl::PendingCopy*> wanted;
    for (int t : images)
        if (Impl::PendingCopy* copy = impl_->images[size_t(t)].copy.get()) wanted.push_back(copy);
    std::sort(wanted.begin(), wanted.end());
    wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
    tbb::parallel_for(size_t(0), wanted.size(), [&](size_t k) {
        std::call_once(wanted[k]->once, [&] { impl_->makeCopy(*wanted[k]); });
    });
}

void TextureResolver::standardNodes(int root, std::vector<int>& out) const {
    if (root < 0 || size_t(root) >= programs_.size()) return;
    for (const Op& op : programs_[size_t(root)])
        if (op.type == TextureType::Standard) out.push_back(op.texture);
}

void TextureResolver::compilePrograms() {
    programs_.resize(scene_.textures.size());
    auto compile = [&](int root) {
        if (root < 0 || !programs_[size_t(root)].empty()) return;
        // The loader bounds the depth (kMaxTextureDepth), so this recursion is bounded too.
        std::vector<int> slotOf(scene_.textures.size(), -1), order;
        visit(scene_, root, slotOf, order);
        std::vector<Op>& program = programs_[size_t(root)];
        for (int t : order) {
            const Texture& tex = scene_.textures[size_t(t)];
            Op op{tex.type, t, -1, -1, -1};
            if (tex.type == TextureType::Layered)
                op.upper = slotOf[size_t(tex.upper)], op.lower = slotOf[size_t(tex.lower)],
                op.mask = slotOf[size_t(tex.mask)];
            program.push_back(op);
        }
    };
    for (const Shader& sh : scene_.shaders)
        forEachTree(sh, compile);
}

TextureResolver::TextureResolver(const Scene& scene, double cacheMiB, bool filtered, bool wide,
                                 const std::string& scratch)
    : scene_(scene), wide_(wide) {
    compilePrograms();
    int standard = 0;
    for (const Texture& t : scene.textures)
        standard += t.type == TextureType::Standard;
    if (standard == 0) return;
    impl_ = std::make_unique<Impl>();
    impl_->filtered = filtered;
    impl_->wide = wide;
    impl_->scratch = scratchFolder(scratch);
    impl_->cache = OIIO::ImageCache::create(false);
    impl_->cache->attribute("max_memory_MB", float(cacheMiB));
    // Colours as the file stores them: OpenImageIO would premultiply a PNG's colour by its alpha
    // on reading (darkening a grey-and-alpha or RGBA base colour wherever alpha < 1), where glTF's
    // base colour and every other image Spillway reads are straight colour, the alpha apart.
    impl_->cache->attribute("unassociatedalpha", 1);
    // Keep every texture file open if the process may (OpenImageIO's default of 100 made the
    // production scene's 448 files re-open 1400 times a render), half the descriptors at most.
    rlimit files{};
    const rlim_t allowed = getrlimit(RLIMIT_NOFILE, &files) == 0 ? files.rlim_cur / 2 : 100;
    impl_->cache->attribute(
        "max_open_files",
        int(std::clamp<rlim_t>(rlim_t(standard) + 16, 100, std::max<rlim_t>(allowed, 100))));
    impl_->images.resize(scene.textures.size());
    // Emission maps are read whole, once (finestLevel): they need no tiled copy.
    std::vector<bool> readWhole(scene.textures.size(), false);
    for (const Shader& sh : scene.shaders)
        if (sh.emissionTexture >= 0) readWhole[size_t(sh.emissionTexture)] = true;
    double heldBytes = 0.0; // what the cache would hold of the images hit setup reads
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        if (t.type != TextureType::Standard) continue;
        Impl::Image& img = impl_->images[i];
        openImage(scene, *impl_, t, img, readWhole[i]);
        img.firstHeld = impl_->heldSlots;
        impl_->heldSlots += img.levels.size();
        if (readWhole[i]) continue;
        for (const Impl::Level& level : img.levels)
            heldBytes += double(level.width) * double(level.height) * double(img.channels) *
                         (img.eightBit ? 1.0 : 4.0);
    }
    outgrowsCache_ = heldBytes > cacheMiB * 1048576.0;
    // The tiles the threads hold together stay within a quarter of the cache.
    const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
    impl_->heldLimit = size_t(cacheMiB * 1048576.0 / 4.0) / size_t(workers);
    // The copies are made during the render: a scratch folder that cannot hold one is named now,
    // before the first ray (a runtime error, not the scene's).
    if (!impl_->pending.empty()) ::close(openScratchFile(impl_->scratch, "texture tile"));
}

TextureResolver::~TextureResolver() = default;

void TextureResolver::checkErrors() const {
    if (!impl_ || !impl_->failed.load()) return;
    std::lock_guard<std::mutex> lock(impl_->errorMutex);
    const Texture& t = scene_.textures[size_t(impl_->failedTexture)];
    std::string why = impl_->error;
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r'))
        why.pop_back();
    if (impl_->failedOnDisk)
        throw std::runtime_error("the tiled copy of texture file '" + t.path +
                                 "' cannot be made: " + why);
    throw SceneError(scene_.file, t.line, "texture file '" + t.path + "' cannot be read: " + why);
}

void TextureResolver::noteCacheUse() const {
    if (!impl_) return;
    long long used = 0;
    impl_->cache->getattribute("stat:cache_memory_used", OIIO::TypeDesc::INT64, &used);
    std::uint64_t seen = impl_->peakCacheBytes.load();
    while (std::uint64_t(used) > seen && !impl_->peakCacheBytes.compare_exchange_weak(seen, used)) {
    }
}

TextureStatistics TextureResolver::statistics() const {
    TextureStatistics s;
    if (!impl_) return s;
    noteCacheUse();
    OIIO::ImageCache& ic = *impl_->cache;
    // OpenImageIO answers a counter only when asked in its own type, int64 for some, int for
    // others (and the choice has moved between versions): ask in both.
    auto count = [&](const char* name) {
        long long wide = 0;
        if (ic.getattribute(name, OIIO::TypeDesc::INT64, &wide)) return std::uint64_t(wide);
        int narrow = 0;
        if (ic.getattribute(name, OIIO::TypeDesc::INT, &narrow)) return std::uint64_t(narrow);
        return std::uint64_t(0);
    };
    s.lookups = impl_->lookups.load();
    s.tilesRead = count("stat:tiles_created");
    s.bytesRead = count("stat:bytes_read");
    s.filesOpened = count("stat:open_files_created");
    const std::uint64_t unique = count("stat:unique_files");
    s.filesReopened = s.filesOpened > unique ? s.filesOpened - unique : 0;
    s.cacheMisses = count("stat:find_tile_cache_misses");
    s.peakCacheBytes = impl_->peakCacheBytes.load();
    std::lock_guard<std::mutex> lock(impl_->copyMutex);
    s.tiledCopies = impl_->copies.size();
    for (const auto& copy : impl_->copies)
        s.tiledCopyBytes += copy->bytes();
    s.tiledCopySeconds = impl_->tiledCopySeconds;
    return s;
}

std::vector<vec3> TextureResolver::finestLevel(int texture, int& width, int& height) const {
    const Impl::Image& image = impl_->images[size_t(texture)];
    width = image.levels[0].width;
    height = image.levels[0].height;
    // Read whole, as floats: within the limit of images read whole.
    const Texture& t = scene_.textures[size_t(texture)];
    if (const std::string why = imageSizeProblem(t.path, width, height); !why.empty())
        throw SceneError(scene_.file, t.line, why + " when read whole (an emission texture)");
    std::vector<vec3> out;
    TexelReader(*impl_, impl_->thread(), texture).finestLevel(out);
    checkErrors();
    return out;
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
    const vec3* root = evaluate(shader.texture, n, uv, footprint);
    for (size_t k = 0; k < n; ++k)
        out[k] = root[k] * p.reflectance;
}

void TextureResolver::values(int tree, size_t n, const vec2* uv, const float* footprint,
                             vec3* out) const {
    const vec3* root = evaluate(tree, n, uv, footprint);
    std::copy(root, root + n, out);
}

namespace {
// Fewer lookups than this are blended one at a time (the reference backend's single lookups
// among them): their 3 n channels fill no vector.
constexpr size_t kWideBlendFrom = 8;
} // namespace

const vec3* TextureResolver::evaluate(int tree, size_t n, const vec2* uv,
                                      const float* footprint) const {
    const std::vector<Op>& program = programs_[size_t(tree)];
    Impl::ThreadState* thread = impl_ ? &impl_->thread() : nullptr;
    // Every node's values for every hit: nodes x hits, in a per-thread buffer.
    static_assert(sizeof(vec3) == 3 * sizeof(float), "a run's vec3s are rows of floats");
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
        case TextureType::Standard: {
            // OBJ's v grows upwards, image rows downwards. The footprint is isotropic.
            const Texture& tex = scene_.textures[size_t(op.texture)];
            if (impl_->images[size_t(op.texture)].absent) {
                std::fill(v, v + n, vec3(1.0f));
                break;
            }
            const vec2* at = uv;
            const float* width = footprint;
            if (tex.uvTransformed || tex.wraps()) {
                thread_local std::vector<vec2> moved;
                thread_local std::vector<float> widths;
                moved.resize(n), widths.resize(n);
                const Impl::Level& finest = impl_->images[size_t(op.texture)].levels[0];
                for (size_t k = 0; k < n; ++k) {
                    moved[k] =
                        tex.uvTransformed ? vec2(tex.uvTransform * vec3(uv[k], 1.0f)) : uv[k];
                    if (tex.wraps()) moved[k] = wrapped(tex, finest.width, finest.height, moved[k]);
                    widths[k] = footprint ? footprint[k] * tex.footprintScale : 0.0f;
                }
                at = moved.data();
                width = footprint ? widths.data() : nullptr;
            }
            TexelReader(*impl_, *thread, op.texture)
                .lookups(n, at, impl_->filtered ? width : nullptr, v);
            impl_->lookups.fetch_add(n, std::memory_order_relaxed);
            break;
        }
        case TextureType::Layered: {
            // m upper + (1 - m) lower per channel, SIMD-wide over the run's 3 n channels where
            // they fill a vector (with `wide` false, one lookup at a time: the oracle).
            const vec3 *m = &values[size_t(op.mask) * n], *upper = &values[size_t(op.upper) * n],
                       *lower = &values[size_t(op.lower) * n];
            if (wide_ && n >= kWideBlendFrom) {
                blendLayers(3 * n, &m->x, &upper->x, &lower->x, &v->x);
                break;
            }
            for (size_t k = 0; k < n; ++k)
                v[k] = m[k] * upper[k] + (vec3(1.0f) - m[k]) * lower[k];
            break;
        }
        }
    }
    return &values[(program.size() - 1) * n];
}

} // namespace spw
