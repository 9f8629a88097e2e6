// The film's fine levels (film_levels.h): tiles of integer sums, allocated when first reached.
#include "host/image/film_levels.h"

#include <tbb/parallel_for.h>

#include <new>

namespace spw {

FilmLevels::FilmLevels(int levels, size_t tiles) : levels_(levels), tiles_(tiles) {
    if (levels > 0) {
        blocks_.reset(new std::atomic<Block*>[size_t(levels) * tiles]);
        for (size_t i = 0; i < size_t(levels) * tiles; ++i)
            blocks_[i].store(nullptr, std::memory_order_relaxed);
    }
}

FilmLevels::FilmLevels(FilmLevels&& other) noexcept
    : levels_(other.levels_), tiles_(other.tiles_), blocks_(std::move(other.blocks_)) {
    other.levels_ = 0;
}

FilmLevels& FilmLevels::operator=(FilmLevels&& other) noexcept {
    if (this != &other) {
        clear();
        levels_ = other.levels_;
        tiles_ = other.tiles_;
        blocks_ = std::move(other.blocks_);
        other.levels_ = 0;
    }
    return *this;
}

FilmLevels::~FilmLevels() {
    clear();
}

void FilmLevels::clear() {
    if (!blocks_) return;
    for (size_t i = 0; i < size_t(levels_) * tiles_; ++i)
        delete blocks_[i].load(std::memory_order_relaxed);
    blocks_.reset();
}

FilmLevels::Block& FilmLevels::touch(int level, size_t tile) {
    std::atomic<Block*>& slot = blocks_[size_t(level - 1) * tiles_ + tile];
    Block* b = slot.load(std::memory_order_acquire);
    if (b) return *b;
    Block* fresh = new Block;
    for (std::atomic<std::int64_t>& v : fresh->lo)
        v.store(0, std::memory_order_relaxed);
    // Another thread may have allocated the tile meanwhile: its block wins.
    if (slot.compare_exchange_strong(b, fresh, std::memory_order_acq_rel)) return *fresh;
    delete fresh;
    return *b;
}

FilmLevels::Fixed FilmLevels::at(int level, size_t tile, size_t slot) const {
    const Block* b = block(level, tile);
    if (!b) return 0;
    const std::int64_t lo = b->lo[slot].load(std::memory_order_relaxed);
    if (!b->hi) return lo;
    return Fixed(b->hi[slot]) * (Fixed(1) << 64) + Fixed(std::uint64_t(lo));
}

bool FilmLevels::holdsLevel(int level) const {
    for (size_t t = 0; t < tiles_; ++t)
        if (holds(level, t)) return true;
    return false;
}

void FilmLevels::zero() {
    if (!blocks_) return;
    tbb::parallel_for(size_t(0), size_t(levels_) * tiles_, [&](size_t i) {
        if (Block* b = blocks_[i].load(std::memory_order_relaxed)) {
            for (std::atomic<std::int64_t>& v : b->lo)
                v.store(0, std::memory_order_relaxed);
            b->hi.reset();
        }
    });
}

void FilmLevels::set(int level, size_t tile, size_t slot, Fixed v) {
    if (v == 0 && !holds(level, tile)) return;
    Block& b = touch(level, tile);
    if (!b.hi && v != Fixed(std::int64_t(v))) widen(b);
    b.lo[slot].store(std::int64_t(std::uint64_t(v)), std::memory_order_relaxed);
    if (b.hi) b.hi[slot] = std::int64_t(v >> 64); // arithmetic: the high word's sign
}

void FilmLevels::widen(Block& b) {
    b.hi.reset(new std::int64_t[kSlots]);
    for (size_t k = 0; k < kSlots; ++k)
        b.hi[k] = b.lo[k].load(std::memory_order_relaxed) < 0 ? -1 : 0;
}

void FilmLevels::add(const FilmLevels& other) {
    if (!other.blocks_) return;
    if (!blocks_) *this = FilmLevels(other.levels_, other.tiles_);
    tbb::parallel_for(size_t(0), size_t(levels_) * tiles_, [&](size_t i) {
        const int level = int(i / tiles_) + 1;
        const size_t tile = i % tiles_;
        const Block* from = other.block(level, tile);
        if (!from) return;
        Block& to = touch(level, tile);
        for (size_t s = 0; s < kSlots; ++s) {
            const Fixed v = other.at(level, tile, s);
            if (v == 0) continue;
            const std::int64_t lo = to.lo[s].load(std::memory_order_relaxed);
            std::int64_t sum;
            if (!to.hi && v == Fixed(std::int64_t(v)) &&
                !__builtin_add_overflow(lo, std::int64_t(v), &sum)) {
                to.lo[s].store(sum, std::memory_order_relaxed);
                continue;
            }
            if (!to.hi) widen(to);
            set(level, tile, s, at(level, tile, s) + v);
        }
    });
}

size_t FilmLevels::bytes() const {
    size_t n = blocks_ ? size_t(levels_) * tiles_ * sizeof(std::atomic<Block*>) : 0;
    for (size_t i = 0; blocks_ && i < size_t(levels_) * tiles_; ++i)
        if (const Block* b = blocks_[i].load(std::memory_order_relaxed))
            n += sizeof(Block) + (b->hi ? kSlots * sizeof(std::int64_t) : 0);
    return n;
}

} // namespace spw
