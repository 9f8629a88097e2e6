// The texture system's insides, shared by textures.cpp (texture trees resolved per hit) and
// texel_reader.cpp (the filter): the ImageCache with the images it has opened and the tiles each
// thread holds (TextureResolver::Impl), and TexelReader, the bilinear and trilinear filter over
// those tiles. Internal to host/textures/.
#pragma once

#include "host/textures/textures.h"
#include "host/textures/tiled_copy.h"
#include "host/textures/wide_texels.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagecache.h>

#include <tbb/enumerable_thread_specific.h>

#include <array>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace spw {

// The most MIP levels read of an image (a 2^31-texel side has 32).
constexpr size_t kMaxLevels = 32;

struct TextureResolver::Impl {
    OIIO::ImageCache* cache = nullptr;
    // The readers of embedded images (Texture::embedded), alive as long as the cache.
    std::vector<std::unique_ptr<OIIO::Filesystem::IOProxy>> proxies;
    struct Level {
        int x = 0, y = 0, width = 1, height = 1; // the data window
    };
    // A tiled copy (tiled_copy.h) not made when the images are opened: made on the first lookup
    // that reads its image, once, by whichever thread asks first; prepare() makes the copies of
    // a batch's images in parallel before its lookups. Shared by the Standard textures that
    // read one image in one encoding.
    struct PendingCopy {
        std::once_flag once;
        const Texture* texture = nullptr;
        OIIO::ustring name;
        OIIO::ImageSpec spec; // the source's first level
        bool srgb = false;
        OIIO::ImageCache::ImageHandle* handle = nullptr; // set within `once`
        std::string error;                               // why not, where it could not be made
        bool diskFailed = false; // it could not be made (the scratch folder, memory), not read
    };
    struct Image {
        OIIO::ImageCache::ImageHandle* handle = nullptr;
        std::shared_ptr<PendingCopy> copy; // null: `handle` is the image's own
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
    // Tiled copies of large untiled images (tiled_copy.h): those to make, by file and encoding;
    // those made (under copyMutex, with the time they took); the folder they go to.
    std::map<std::string, std::shared_ptr<PendingCopy>> pending;
    std::vector<std::unique_ptr<TiledCopy>> copies;
    std::mutex copyMutex;
    std::atomic<size_t> copiesTried{0}; // the pending copies makeCopy has run for
    std::string scratch;
    double tiledCopySeconds = 0.0;
    // The pending copy of Standard texture t's image `name` (first level `spec`) in its encoding.
    std::shared_ptr<PendingCopy> pendingCopy(const Texture& t, OIIO::ustring name,
                                             const OIIO::ImageSpec& spec, bool srgb);
    // Makes `copy` (within its once_flag); where it cannot be, copy.error says why.
    void makeCopy(PendingCopy& copy);
    // The handle lookups of Standard texture `index` read, its tiled copy made first where it
    // has one; null (and the render failed, reported after the iteration) where it cannot be.
    OIIO::ImageCache::ImageHandle* handleOf(const Image& img, int index) {
        if (!img.copy) return img.handle;
        std::call_once(img.copy->once, [&] { makeCopy(*img.copy); });
        if (!img.copy->handle) fail(index, img.copy->error, img.copy->diskFailed);
        return img.copy->handle;
    }
    // The first failed lookup, reported after the iteration (a lookup cannot throw mid-batch).
    std::atomic<bool> failed{false};
    std::mutex errorMutex;
    int failedTexture = -1;
    std::string error;
    bool failedOnDisk = false; // a runtime failure (exit 1), not the image's (exit 2)
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
    void fail(int index, std::string why = "", bool onDisk = false) {
        if (failed.exchange(true)) return;
        std::lock_guard<std::mutex> lock(errorMutex);
        failedTexture = index;
        failedOnDisk = onDisk;
        error = why.empty() ? cache->geterror() : why;
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
    void lookups(size_t n, const vec2* uv, const float* footprint, vec3* out);

    // Every texel of the finest level, row by row.
    void finestLevel(std::vector<vec3>& out);

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
    void filterLevel(const LevelQuery* queries, size_t n, int up, vec3* out);

    // out[hitOf[k]] = bilinear(level, lanes.s.v[k], lanes.t.v[k]) for k in [0, count): the hits in
    // the tile held for the level SIMD-wide; then the first of those left one at a time (which
    // holds its tile), and the rest wide again, until none is left. Overwrites the lanes.
    void filterBlock(int level, TexelLanes& lanes, std::uint32_t* hitOf, size_t count, vec3* out);

    // The tile held for a level as the wide filter reads it (bytes 0: none).
    TexelTile heldTile(int levelIndex) const;
    TexelLevel levelView(int levelIndex) const;

    // A texel index on a periodic level of n texels, for the i in [-1, n - 1] that bilinear()
    // makes from a coordinate in [0, 1] (no division on this path).
    static int wrap(int i, int n) { return i < 0 ? i + n : i; }

    vec3 bilinear(int levelIndex, float s, float t);

    // The texel at (x, y) of a level (data window coordinates), through the tile held for it.
    vec3 texel(int levelIndex, int x, int y);

    // The pixel at p as linear values: its channels from Texture::channel on, up to three (a
    // one-channel image's value in all three), 8- and 16-bit integers in [0, 1], sRGB-encoded
    // images linearised per texel, before filtering (8-bit ones through a table). The cache
    // keeps 8- and 16-bit integers, half and float as they are in the file, and anything else as
    // float.
    vec3 decode(const Held& h, const unsigned char* texel) const;

    static const std::array<float, 256>& srgbTable();

    static const std::array<float, 256>& linearTable();

    static size_t channelBytes(OIIO::TypeDesc::BASETYPE type);

    // Channel c of a pixel of a format other than 8-bit.
    static float channel(const unsigned char* p, int c, OIIO::TypeDesc::BASETYPE type);

    Impl& impl_;
    Impl::ThreadState& thread_;
    int index_;
    const Impl::Image& image_;
    Held* held_; // this image's levels' slots in the thread's table
};

} // namespace spw
