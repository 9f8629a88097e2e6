// The film's fine levels: where a contribution too small for the film's home grid is summed.
//
// The home grid (film.h) is set from the scene's brightest emitter, so that its sample sits at
// 2^40 units. A contribution is kept to float precision when it is at least 2^24 units of the
// grid it is rounded on (a rounding moves it by less than one unit); below that, on the home
// grid alone, it would lose its precision, and far below it would round to 0 or to one unit
// almost always (one 1e20 light anywhere made every other pixel 0 or a spike). Such a
// contribution goes instead to the fine level k >= 1 where it is at least 2^24 units, a level's
// unit being 2^-(bits x k) home units: there it is rounded as on the home grid, to a relative
// 2^-24 of itself, and so of the pixel it adds to (the film's sums are of non-negative radiance).
// Each level is a sum of integers, exact in any order, so the film stays bit for bit the same
// for any thread count, batch or grouping of iterations; the image reads each pixel's home sum
// and then its levels, finest last, in double.
//
// Levels are held by 8 x 8 tile, allocated the first time a contribution reaches the tile at that
// level: a scene whose contributions all fit the home grid holds none.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace spw {

class FilmLevels {
  public:
    using Fixed = __int128;
    static constexpr int kTile = 8;                             // Film::kAdaptiveTile
    static constexpr size_t kSlots = size_t(kTile * kTile) * 6; // a tile's (r, g, b) x 2 halves

    FilmLevels() = default;
    FilmLevels(int levels, size_t tiles);
    FilmLevels(FilmLevels&& other) noexcept;
    FilmLevels& operator=(FilmLevels&& other) noexcept;
    FilmLevels(const FilmLevels&) = delete;
    FilmLevels& operator=(const FilmLevels&) = delete;
    ~FilmLevels();

    int levels() const { return levels_; }
    // Thread-safe: adds q to slot `slot` of tile `tile` at level `level` (1 .. levels()).
    void add(int level, size_t tile, size_t slot, std::int64_t q) {
        Block* b = block(level, tile);
        (b ? *b : touch(level, tile)).lo[slot].fetch_add(q, std::memory_order_relaxed);
    }
    // Sets it (not thread-safe).
    void set(int level, size_t tile, size_t slot, Fixed v);
    // The sum there (0 where the tile holds nothing at that level).
    Fixed at(int level, size_t tile, size_t slot) const;
    bool holds(int level, size_t tile) const { return block(level, tile) != nullptr; }
    // Where the sum lies, or null while the tile holds nothing at that level (for prefetching).
    const void* address(int level, size_t tile, size_t slot) const {
        const Block* b = level <= levels_ ? block(level, tile) : nullptr;
        return b ? &b->lo[slot] : nullptr;
    }
    // Whether any tile holds the level.
    bool holdsLevel(int level) const;
    // Zeroes every sum, keeping the tiles' memory for the next iteration.
    void zero();
    // Adds other's sums into these (not thread-safe), widening a sum to 128 bits where it could
    // pass 64.
    void add(const FilmLevels& other);
    // Bytes held.
    size_t bytes() const;

  private:
    struct Block {
        std::atomic<std::int64_t> lo[kSlots];
        std::unique_ptr<std::int64_t[]> hi; // the high words, once a sum could pass 2^63
    };
    Block* block(int level, size_t tile) const {
        return blocks_ ? blocks_[size_t(level - 1) * tiles_ + tile].load(std::memory_order_acquire)
                       : nullptr;
    }
    Block& touch(int level, size_t tile);
    static void widen(Block& b); // every sum sign-extended into its high word
    void clear();

    int levels_ = 0;
    size_t tiles_ = 0;
    std::unique_ptr<std::atomic<Block*>[]> blocks_; // level-major; null: not yet allocated
};

} // namespace spw
