#include "host/textures/textures.h"

#include "host/image/image_io.h"
#include "host/textures/wide_texels.h"

#include "shared/texture_wrap.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/half.h>
#include <OpenImageIO/imagecache.h>

#include <sys/resource.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace spw {

// The most MIP levels read of an image (a 2^31-texel side has 32).
constexpr size_t kMaxLevels = 32;

struct TextureResolver::Impl {
    OIIO::ImageCache* cache = nullptr;
    // The readers of embedded images (Texture::bytes), alive as long as the cache.
    std::vector<std::unique_ptr<OIIO::Filesystem::IOMemReader>> proxies;
    struct Level {
        int x = 0, y = 0, width = 1, height = 1; // the data window
    };
    struct Image {
        OIIO::ImageCache::ImageHandle* handle = nullptr;
        bool srgb = false;
        bool eightBit = false;     // its texels are 8-bit integers (the wide filter reads those)
        int channels = 3;          // from Texture::channel on
        int firstChannel = 0;      // Texture::channel
        bool absent = false;       // the image has no channel Texture::channel: every value is 1
        float finest = 1.0f;       // the finest level's larger side, texels
        std::vector<Level> levels; // finest first
        size_t firstHeld = 0;      // its levels' slots in ThreadState::held
    };
    std::vector<Image> images; // parallel to Scene::textures (only Standard entries are used)
    // The first failed lookup, reported after the iteration (a lookup cannot throw mid-batch).
    std::atomic<bool> failed{false};
    std::mutex errorMutex;
    int failedTexture = -1;
    std::string error;
    mutable std::atomic<std::uint64_t> peakCacheBytes{0};
    std::atomic<std::uint64_t> lookups{0};
    bool filtered = true;
    bool wide = true; // runs of 8-bit lookups filtered SIMD-wide
    // A tile a thread holds a reference to (so the cache cannot evict it), with what reading its
    // pixels needs.
    struct Held {
        OIIO::ImageCache::Tile* tile = nullptr;
        int x0 = 0, y0 = 0, x1 = 0, y1 = 0; // the tile's pixels, [x0, x1) x [y0, y1)
        const unsigned char* pixels = nullptr;
        size_t pixelBytes = 0, rowBytes = 0;
        OIIO::TypeDesc::BASETYPE type = OIIO::TypeDesc::UINT8;
        bool holds(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
        const unsigned char* at(int x, int y) const {
            return pixels + size_t(y - y0) * rowBytes + size_t(x - x0) * pixelBytes;
        }
        size_t bytes() const { return rowBytes * size_t(y1 - y0); }
    };
    // What each thread keeps between lookups: its OpenImageIO state (made by this cache and
    // destroyed before it), and the last tile it read of each image's each MIP level, so that
    // the next lookup near the last one, in any image, finds its texels without asking the
    // cache. A sorted run of hits and a depth-first tracer's neighbouring pixels both gain.
    // The tiles a thread holds are bounded by `heldLimit` bytes: past it, it lets them all go.
    // (OpenImageIO's own per-thread state, whose life is the thread's, was tried first: a render
    // after another in one process, TBB's workers living on, aborted inside OpenImageIO, its
    // tile accounting gone negative, in 19 of 20 runs of the TextureFilter tests.)
    struct ThreadState {
        OIIO::ImageCache::Perthread* oiio = nullptr;
        std::vector<Held> held;             // Image::firstHeld + level
        std::vector<std::uint32_t> holding; // the slots of `held` with a tile
        size_t heldBytes = 0;
    };
    tbb::enumerable_thread_specific<ThreadState> threads;
    size_t heldSlots = 0, heldLimit = 0;
    ThreadState& thread() {
        ThreadState& mine = threads.local();
        if (!mine.oiio) {
            mine.oiio = cache->create_thread_info();
            mine.held.resize(heldSlots);
        }
        return mine;
    }
    void letGo(ThreadState& t, std::uint32_t keep = ~0u) {
        for (std::uint32_t slot : t.holding) {
            if (slot == keep || !t.held[slot].tile) continue;
            cache->release_tile(t.held[slot].tile);
            t.held[slot] = Held{};
        }
        t.holding.clear();
        t.heldBytes = 0;
        if (keep != ~0u && t.held[keep].tile) {
            t.holding.push_back(keep);
            t.heldBytes = t.held[keep].bytes();
        }
    }
    void fail(int index) {
        if (failed.exchange(true)) return;
        std::lock_guard<std::mutex> lock(errorMutex);
        failedTexture = index;
        error = cache->geterror();
        if (error.empty()) error = "a tile could not be read";
    }
    ~Impl() {
        if (!cache) return;
        for (ThreadState& t : threads) {
            letGo(t);
            if (t.oiio) cache->destroy_thread_info(t.oiio);
        }
        OIIO::ImageCache::destroy(cache);
    }
};

namespace {

// The texels of one image that a run of lookups reads, through the tiles the thread holds.
class TexelReader {
  public:
    using Impl = TextureResolver::Impl;
    using Held = Impl::Held;
    TexelReader(Impl& impl, Impl::ThreadState& thread, int index)
        : impl_(impl), thread_(thread), index_(index), image_(impl.images[size_t(index)]),
          held_(thread.held.data() + image_.firstHeld) {}

    // The filtered values for n hits at uv[k] (OBJ's v, growing upwards) for footprints
    // footprint[k] (uv units; footprint null: 0): bilinear within a level, blended between the
    // two levels whose texels bracket the footprint's size (trilinear); the finest level alone
    // for footprints under a texel. Repeats in both directions.
    //
    // Level by level: every hit's finer level, then the coarser level of those that blend two,
    // so the tile reads of one file rarely alternate between levels. Within a level, a run of
    // hits whose texels lie in the tile held for it is filtered SIMD-wide (wide_texels.h) where
    // the image is 8-bit; the rest, and other formats, one hit at a time (bilinear(), the
    // oracle the wide filter equals bit for bit).
    void lookups(size_t n, const vec2* uv, const float* footprint, vec3* out) {
        thread_local std::vector<LevelQuery> queries;
        queries.resize(n);
        const int last = int(image_.levels.size()) - 1;
        for (size_t k = 0; k < n; ++k) {
            LevelQuery& q = queries[k];
            q.s = uv[k].x, q.t = 1.0f - uv[k].y;
            q.level = 0, q.blend = -1.0f;
            const float texels = (footprint ? footprint[k] : 0.0f) * image_.finest;
            if (!(texels > 1.0f) || last == 0) continue;
            const float lod = std::log2(texels);
            if (!(lod < float(last))) { // an infinite footprint too
                q.level = last;
                continue;
            }
            q.level = int(lod);
            q.blend = lod - float(q.level);
        }
        filterLevel(queries.data(), n, 0, out);
        thread_local std::vector<vec3> coarse;
        coarse.resize(n);
        filterLevel(queries.data(), n, 1, coarse.data());
        for (size_t k = 0; k < n; ++k) {
            const LevelQuery& q = queries[k];
            if (q.blend >= 0.0f) out[k] = out[k] + q.blend * (coarse[k] - out[k]);
        }
    }

    // Every texel of the finest level, row by row.
    void finestLevel(std::vector<vec3>& out) {
        const Impl::Level& level = image_.levels[0];
        out.resize(size_t(level.width) * size_t(level.height));
        for (int y = 0; y < level.height; ++y)
            for (int x = 0; x < level.width; ++x)
                out[size_t(y) * size_t(level.width) + size_t(x)] =
                    image_.absent ? vec3(1.0f) : texel(0, level.x + x, level.y + y);
    }

  private:
    struct LevelQuery {
        float s, t;  // image space
        int level;   // the finer (or only) level read
        float blend; // toward level + 1; negative: that level alone
    };

    // Fewer hits than this are filtered one at a time: a vector's setup would cost more.
    static constexpr size_t kWideFrom = 4;

    // out[k] = bilinear(q.level + up, q.s, q.t) for the queries q = queries[k] that read that
    // level: every query (up 0), or those that blend two levels (up 1).
    void filterLevel(const LevelQuery* queries, size_t n, int up, vec3* out) {
        auto reads = [&](size_t k) { return up == 0 || queries[k].blend >= 0.0f; };
        if (!(impl_.wide && image_.eightBit && n >= kWideFrom)) {
            for (size_t k = 0; k < n; ++k)
                if (reads(k)) out[k] = bilinear(queries[k].level + up, queries[k].s, queries[k].t);
            return;
        }
        // The hits in order of their level (a counting sort: a run's footprints differ, and its
        // levels with them, so hits of one level would otherwise come a few at a time).
        std::array<std::uint32_t, kMaxLevels + 1> first{};
        for (size_t k = 0; k < n; ++k)
            if (reads(k)) ++first[size_t(queries[k].level + up) + 1];
        for (size_t l = 1; l <= kMaxLevels; ++l)
            first[l] += first[l - 1];
        thread_local std::vector<std::uint32_t> byLevel;
        byLevel.resize(n);
        for (size_t k = 0; k < n; ++k)
            if (reads(k)) byLevel[first[size_t(queries[k].level + up)]++] = std::uint32_t(k);
        // Blocks of one level's hits.
        TexelLanes lanes;
        std::uint32_t hitOf[simd::kBlock];
        size_t count = 0;
        int blockLevel = -1;
        for (size_t i = 0, total = first[kMaxLevels - 1]; i < total; ++i) {
            const std::uint32_t k = byLevel[i];
            const int level = queries[k].level + up;
            if (level != blockLevel || count == simd::kBlock) {
                filterBlock(blockLevel, lanes, hitOf, count, out);
                blockLevel = level;
                count = 0;
            }
            lanes.s.v[count] = queries[k].s, lanes.t.v[count] = queries[k].t, hitOf[count++] = k;
        }
        filterBlock(blockLevel, lanes, hitOf, count, out);
    }

    // out[hitOf[k]] = bilinear(level, lanes.s.v[k], lanes.t.v[k]) for k in [0, count): the hits in
    // the tile held for the level SIMD-wide; then the first of those left one at a time (which
    // holds its tile), and the rest wide again, until none is left. Overwrites the lanes.
    void filterBlock(int level, TexelLanes& lanes, std::uint32_t* hitOf, size_t count, vec3* out) {
        float *const s = lanes.s.v, *const t = lanes.t.v;
        while (count > 0) {
            size_t left = 0;
            const TexelTile tile = heldTile(level);
            if (tile.bytes >= 4 && count >= kWideFrom) {
                const size_t end = simd::wholeVectors(count);
                for (size_t k = count; k < end; ++k) // padding repeats the last lane
                    s[k] = s[count - 1], t[k] = t[count - 1];
                bilinearInTile(tile, levelView(level), end, lanes);
                for (size_t k = 0; k < count; ++k) {
                    if (lanes.done.v[k])
                        out[hitOf[k]] = vec3(lanes.r.v[k], lanes.g.v[k], lanes.b.v[k]);
                    else
                        s[left] = s[k], t[left] = t[k], hitOf[left++] = hitOf[k];
                }
            } else {
                left = count;
            }
            if (left == 0) return;
            out[hitOf[0]] = bilinear(level, s[0], t[0]);
            for (size_t k = 1; k < left; ++k)
                s[k - 1] = s[k], t[k - 1] = t[k], hitOf[k - 1] = hitOf[k];
            count = left - 1;
        }
    }

    // The tile held for a level as the wide filter reads it (bytes 0: none).
    TexelTile heldTile(int levelIndex) const {
        const Held& h = held_[size_t(levelIndex)];
        TexelTile tile;
        if (!h.tile || h.type != OIIO::TypeDesc::UINT8) return tile;
        // The channels read start Texture::channel bytes into each texel.
        tile.pixels = h.pixels + image_.firstChannel;
        tile.x0 = h.x0, tile.y0 = h.y0, tile.x1 = h.x1, tile.y1 = h.y1;
        tile.pixelBytes = int(h.pixelBytes), tile.rowBytes = int(h.rowBytes);
        tile.bytes = int(h.bytes()) - image_.firstChannel;
        tile.channels = std::min(image_.channels, 3);
        tile.decode = image_.srgb ? srgbTable().data() : linearTable().data();
        return tile;
    }
    TexelLevel levelView(int levelIndex) const {
        const Impl::Level& l = image_.levels[size_t(levelIndex)];
        return {l.x, l.y, l.width, l.height};
    }

    // A texel index on a periodic level of n texels, for the i in [-1, n - 1] that bilinear()
    // makes from a coordinate in [0, 1] (no division on this path).
    static int wrap(int i, int n) { return i < 0 ? i + n : i; }

    vec3 bilinear(int levelIndex, float s, float t) {
        const Impl::Level& level = image_.levels[size_t(levelIndex)];
        // Periodic: only the fraction matters, and it keeps far coordinates exact.
        s -= std::floor(s);
        t -= std::floor(t);
        if (!(s >= 0.0f && s <= 1.0f)) s = 0.0f; // a NaN coordinate reads texel 0
        if (!(t >= 0.0f && t <= 1.0f)) t = 0.0f;
        // Texel centres at (i + 0.5) / width.
        const float x = s * float(level.width) - 0.5f, y = t * float(level.height) - 0.5f;
        const float xf = std::floor(x), yf = std::floor(y);
        const float ax = x - xf, ay = y - yf;
        const int x0 = wrap(int(xf), level.width) + level.x,
                  y0 = wrap(int(yf), level.height) + level.y;
        const int x1 = x0 + 1 == level.x + level.width ? level.x : x0 + 1;
        const int y1 = y0 + 1 == level.y + level.height ? level.y : y0 + 1;
        vec3 a, b, c, d;
        const Held& h = held_[size_t(levelIndex)];
        if (h.holds(x0, y0) && h.holds(x1, y1)) {
            // The common case: all four texels in the tile the previous lookup read.
            a = decode(h, h.at(x0, y0)), b = decode(h, h.at(x1, y0));
            c = decode(h, h.at(x0, y1)), d = decode(h, h.at(x1, y1));
        } else {
            a = texel(levelIndex, x0, y0), b = texel(levelIndex, x1, y0);
            c = texel(levelIndex, x0, y1), d = texel(levelIndex, x1, y1);
        }
        const vec3 top = a + ax * (b - a), bottom = c + ax * (d - c);
        return top + ay * (bottom - top);
    }

    // The texel at (x, y) of a level (data window coordinates), through the tile held for it.
    vec3 texel(int levelIndex, int x, int y) {
        Held& h = held_[size_t(levelIndex)];
        if (!h.holds(x, y)) {
            const auto slot = std::uint32_t(image_.firstHeld + size_t(levelIndex));
            if (h.tile) {
                impl_.cache->release_tile(h.tile);
                thread_.heldBytes -= h.bytes();
            } else {
                thread_.holding.push_back(slot);
            }
            h = Held{};
            h.tile = impl_.cache->get_tile(image_.handle, thread_.oiio, 0, levelIndex, x, y, 0);
            if (!h.tile) {
                // The slot holds nothing now (a slot is listed while it holds a tile).
                thread_.holding.erase(
                    std::find(thread_.holding.begin(), thread_.holding.end(), slot));
                impl_.fail(index_);
                return vec3(0.0f);
            }
            const OIIO::ROI roi = impl_.cache->tile_roi(h.tile);
            OIIO::TypeDesc format;
            h.pixels = static_cast<const unsigned char*>(impl_.cache->tile_pixels(h.tile, format));
            h.x0 = roi.xbegin, h.x1 = roi.xend, h.y0 = roi.ybegin, h.y1 = roi.yend;
            h.type = OIIO::TypeDesc::BASETYPE(format.basetype);
            h.pixelBytes = format.size() * size_t(roi.nchannels());
            h.rowBytes = h.pixelBytes * size_t(roi.width());
            if (!h.pixels || !h.holds(x, y)) {
                impl_.fail(index_);
                h.x1 = h.x0, h.y1 = h.y0; // holds nothing
                return vec3(0.0f);
            }
            thread_.heldBytes += h.bytes();
            if (thread_.heldBytes > impl_.heldLimit) impl_.letGo(thread_, slot);
        }
        return decode(h, h.at(x, y));
    }

    // The pixel at p as linear values: its channels from Texture::channel on, up to three (a
    // one-channel image's value in all three), 8- and 16-bit integers in [0, 1], sRGB-encoded
    // images linearised per texel, before filtering (8-bit ones through a table). The cache
    // keeps 8- and 16-bit integers, half and float as they are in the file, and anything else as
    // float.
    vec3 decode(const Held& h, const unsigned char* texel) const {
        const unsigned char* p = texel + size_t(image_.firstChannel) * channelBytes(h.type);
        float v[3] = {0.0f, 0.0f, 0.0f};
        const int nc = std::min(image_.channels, 3);
        if (h.type == OIIO::TypeDesc::UINT8) {
            const std::array<float, 256>& table = image_.srgb ? srgbTable() : linearTable();
            for (int c = 0; c < nc; ++c)
                v[c] = table[p[c]];
        } else {
            for (int c = 0; c < nc; ++c)
                v[c] = image_.srgb ? srgbToLinear(channel(p, c, h.type)) : channel(p, c, h.type);
        }
        return nc == 1 ? vec3(v[0]) : vec3(v[0], v[1], v[2]);
    }

    static const std::array<float, 256>& srgbTable() {
        static const std::array<float, 256> table = [] {
            std::array<float, 256> t{};
            for (int i = 0; i < 256; ++i)
                t[size_t(i)] = srgbToLinear(float(i) * (1.0f / 255.0f));
            return t;
        }();
        return table;
    }

    static const std::array<float, 256>& linearTable() {
        static const std::array<float, 256> table = [] {
            std::array<float, 256> t{};
            for (int i = 0; i < 256; ++i)
                t[size_t(i)] = float(i) * (1.0f / 255.0f);
            return t;
        }();
        return table;
    }

    static size_t channelBytes(OIIO::TypeDesc::BASETYPE type) {
        return type == OIIO::TypeDesc::UINT8                                    ? 1
               : type == OIIO::TypeDesc::UINT16 || type == OIIO::TypeDesc::HALF ? 2
                                                                                : 4;
    }

    // Channel c of a pixel of a format other than 8-bit.
    static float channel(const unsigned char* p, int c, OIIO::TypeDesc::BASETYPE type) {
        switch (type) {
        case OIIO::TypeDesc::UINT16: {
            std::uint16_t u;
            std::memcpy(&u, p + 2 * c, 2);
            return float(u) * (1.0f / 65535.0f);
        }
        case OIIO::TypeDesc::HALF: {
            half h;
            std::memcpy(&h, p + 2 * c, 2);
            return float(h);
        }
        default: {
            float f;
            std::memcpy(&f, p + 4 * c, 4);
            return f;
        }
        }
    }

    Impl& impl_;
    Impl::ThreadState& thread_;
    int index_;
    const Impl::Image& image_;
    Held* held_; // this image's levels' slots in the thread's table
};

} // namespace

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
// its channels, encoding and MIP levels. Throws where the image cannot be read.
void openImage(TextureResolver::Impl& impl, const Texture& t, TextureResolver::Impl::Image& img) {
    OIIO::ustring name(t.path);
    if (t.bytes) { // embedded: read from memory, through a proxy the cache keeps using
        auto& proxy = impl.proxies.emplace_back(std::make_unique<OIIO::Filesystem::IOMemReader>(
            const_cast<char*>(t.bytes->data()), t.bytes->size()));
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
    img.firstChannel = std::max(t.channel, 0);
    img.absent = img.firstChannel >= spec->nchannels;
    img.channels = img.absent ? 1 : spec->nchannels - img.firstChannel;
    img.eightBit = spec->format == OIIO::TypeDesc::UINT8;
    std::string cs = spec->get_string_attribute("oiio:ColorSpace");
    img.srgb = !t.linear && (cs == "sRGB" || (cs.empty() && spec->format == OIIO::TypeDesc::UINT8));
    img.finest = float(std::max(spec->width, spec->height));
    // Its MIP levels, as many as the file has (an image without them is its own only level).
    for (int level = 0; level < int(kMaxLevels); ++level) {
        const OIIO::ImageSpec* ls =
            level == 0 ? spec : impl.cache->imagespec(img.handle, nullptr, 0, level);
        if (!ls || ls->width < 1 || ls->height < 1) break;
        img.levels.push_back({ls->x, ls->y, ls->width, ls->height});
    }
}

} // namespace

TextureResolver::TextureResolver(const Scene& scene, double cacheMiB, bool filtered, bool wide)
    : scene_(scene), wide_(wide) {
    programs_.resize(scene.textures.size());
    auto compile = [&](int root) {
        if (root < 0 || !programs_[size_t(root)].empty()) return;
        // The loader bounds the depth (kMaxTextureDepth), so this recursion is bounded too.
        std::vector<int> slotOf(scene.textures.size(), -1), order;
        visit(scene, root, slotOf, order);
        std::vector<Op>& program = programs_[size_t(root)];
        for (int t : order) {
            const Texture& tex = scene.textures[size_t(t)];
            Op op{tex.type, t, -1, -1, -1};
            if (tex.type == TextureType::Layered)
                op.upper = slotOf[size_t(tex.upper)], op.lower = slotOf[size_t(tex.lower)],
                op.mask = slotOf[size_t(tex.mask)];
            program.push_back(op);
        }
    };
    for (const Shader& sh : scene.shaders) {
        compile(sh.texture);
        compile(sh.normalTexture);
        compile(sh.metallicRoughnessTexture);
        if (sh.cutout.enabled) compile(sh.cutout.texture);
    }
    int standard = 0;
    for (const Texture& t : scene.textures)
        standard += t.type == TextureType::Standard;
    if (standard == 0) return;
    impl_ = std::make_unique<Impl>();
    impl_->filtered = filtered;
    impl_->wide = wide;
    impl_->cache = OIIO::ImageCache::create(false);
    impl_->cache->attribute("max_memory_MB", float(cacheMiB));
    // Keep every texture file open if the process may (OpenImageIO's default of 100 made the
    // production scene's 448 files re-open 1400 times a render), half the descriptors at most.
    rlimit files{};
    const rlim_t allowed = getrlimit(RLIMIT_NOFILE, &files) == 0 ? files.rlim_cur / 2 : 100;
    impl_->cache->attribute(
        "max_open_files",
        int(std::clamp<rlim_t>(rlim_t(standard) + 16, 100, std::max<rlim_t>(allowed, 100))));
    impl_->images.resize(scene.textures.size());
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        if (t.type != TextureType::Standard) continue;
        Impl::Image& img = impl_->images[i];
        openImage(*impl_, t, img);
        img.firstHeld = impl_->heldSlots;
        impl_->heldSlots += img.levels.size();
    }
    // The tiles the threads hold together stay within a quarter of the cache.
    const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
    impl_->heldLimit = size_t(cacheMiB * 1048576.0 / 4.0) / size_t(workers);
}

TextureResolver::~TextureResolver() = default;

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
    return s;
}

std::vector<vec3> TextureResolver::finestLevel(int texture, int& width, int& height) const {
    const Impl::Image& image = impl_->images[size_t(texture)];
    width = image.levels[0].width;
    height = image.levels[0].height;
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
