// The film. Samples are splatted through the pixel filter into 64-bit fixed-point accumulators
// with atomic integer adds: integer addition is associative, so an iteration's sums are the
// same bit for bit whatever the thread count, batch size or order in which paths finish. Each
// value is rounded to the fixed-point grid stochastically with a hash of the sample's key, so
// the rounding is unbiased and still deterministic. At the end of an iteration the integer sums
// are added, pixel by pixel, into 128-bit integer accumulators that hold the whole render: the
// film is exact end to end, so sums of any iterations, added in any grouping (checkpoints,
// partial renders merged later), give the same image bit for bit.
//
// Precision: a contribution is rounded where it is at least 2^24 units, so that it keeps float
// precision relative to itself and so to its pixel: on the home grid below, or, when it is
// smaller than that there (far below the brightest emitter), on a fine level of its own
// magnitude (film_levels.h), down to the smallest float.
//
// Memory (per pixel): the iteration's sums, 64 bytes; the whole render's, 64 bytes while every
// sum fits 64 bits, which at the usual scale of 2^40 is 2^23 samples of the brightest emitter
// in one pixel (the high halves, 64 bytes more, are added the first time a sum could pass 2^63);
// and in each 8 x 8 tile a fine level reaches, 48 bytes a pixel for the iteration and 48 (96
// once widened) for the render.
// Sample counts are kept per 8 x 8 tile. The first iteration's sums become the whole render's
// without a copy, and the next iteration's are only allocated when it begins: a render of one
// iteration holds 64 bytes a pixel, of more iterations 128.
//
// No accumulator can wrap: at most N = (samples per pixel and iteration) x (pixels a filter
// reaches) adds land in one in an iteration, and each add is clamped (and counted as saturated)
// at 2^62 / N. The fixed-point scale puts one sample of the scene's brightest emitter at 2^40,
// or lower where N needs it, keeping at least 2^16 of headroom below the clamp; the weights sit
// at 2^40 or below the clamp likewise. For the usual N (up to 64) that is 2^40 and a clamp 2^20
// times the brightest emitter. Non-finite samples are counted and dropped, never added.
//
// Wide filters (Tent, Gaussian): one film write per camera sample. A sample's contributions
// (emission, shadow rays, escapes) are summed into its own sum, 3 doubles in home units in a
// per-iteration sample buffer indexed by the path's id, and finishSamples() filters each sum
// once through the footprint, with the sample's filter weight, in pixel order, rounding each add
// (clamped and counted at the clamp of one add). A path's contributions arrive one bounce after
// another on every backend, in the same order, so its double sum is the same for any thread
// count or batch. The Box filter reaches one
// pixel, so its contributions go straight to the film, and no sample buffer is allocated.
//
// The samples accumulate in two half buffers, whose difference estimates the image's own error
// without a reference (halfBufferRelMse); that needs the halves to be independent and
// identically distributed. By stratum (Independent, Grid, Stratified), a sample's half is
// (iteration + its index within the iteration) mod 2: over any two iterations each half takes
// every stratum of the Stratified and Grid samplers once. By stream (Sobol), it is the sample
// index mod 2: the sampler's two independent scrambled sequences (shared/rng.h, rand4).
//
// Adaptive sampling (setAdaptive): the image is cut into 8 x 8 tiles, as MoonRay does; after each
// whole iteration a tile whose pixels have at least the minimum samples and whose error
// estimate, sqrt of the mean over its pixels and channels of the half-buffer relMSE's terms
// (halfBufferTermRows), as a relative RMS error, is below the threshold stops taking samples
// (sampling() false), and takes them again should its estimate rise above it. The decision reads
// only the film's sums and per-pixel sample counts after whole iterations, so it is the same for
// any thread count, batch size or backend, and a checkpoint (which keeps both) resumes it
// exactly. A tile estimates more steadily than a pixel: 192 values rather than 3, so a pixel
// that drew a few lucky samples does not stop early.
#pragma once

#include "host/image/film_levels.h"
#include "host/image/filter.h"
#include "shared/types.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace spw {

struct FootprintLanes;
struct FootprintAdds;

// The stochastic-rounding key of a contribution: every backend uses the same one, so that
// backends tracing the same paths produce the same film bit for bit.
inline uint filmKey(uint pathId, uint bounce, bool shadow) {
    return (pathId * 64u + bounce) ^ (shadow ? 0x80000000u : 0u);
}

class Film {
  public:
    // The whole render's sums: 2^62 per iteration at most, so 2^65 iterations before they could
    // wrap.
    using Fixed = __int128;

    // Which half buffer a sample goes to (above).
    enum class Halves { ByStratum, ByStream };

    // `samplesPerIteration`: camera samples per pixel in one iteration (sample base^2).
    Film(int width, int height, const Filter& filter, float brightestRadiance,
         int samplesPerIteration = 1, Halves halves = Halves::ByStratum);

    int width() const { return width_; }
    int height() const { return height_; }

    // Before each iteration's samples (the constructor begins the first): clears the
    // iteration's sums. Between endIteration() and this, lastIterationImage() is that
    // iteration's image.
    void beginIteration();
    // Whether a sample's contributions are summed before they are filtered (every filter but
    // Box): then splat() and prefetch() do not read their film position.
    bool sumsSamples() const { return filter_.type != FilterType::Box; }
    // Thread-safe. Once per camera sample: adds the sample's filter weight (or, when the film
    // sums samples, notes where the sample lies, and finishSamples() adds it). `path`: the
    // sample's path id within the iteration, pixel x samples per iteration + sample. (Samples
    // are counted by tile at endIteration(): every pixel of a sampling tile takes the
    // iteration's samples.)
    void addSample(uint path, vec2 filmPos, uint sampleIndex);
    // Thread-safe. Any number of times per sample: adds radiance it carried to the camera.
    // `key` makes the stochastic rounding deterministic (filmKey()). When the film sums samples,
    // a path's contributions must arrive in path order (as every backend makes them: by bounce,
    // the emission before the shadow ray), and filmPos is not read.
    void splat(uint path, vec2 filmPos, uint sampleIndex, vec3 radiance, uint key);
    // Thread-safe. splat() of each of splats[0, n), n <= kSplatBatch, in order, with the same
    // sums bit for bit: the batch is rounded SIMD-wide (roundFootprint), then added in order.
    struct Splat {
        vec2 pos;
        uint path;
        uint sample;
        uint key;
        vec3 value;
    };
    static constexpr size_t kSplatBatch = 64;
    void splat(const Splat* splats, size_t n);
    // A hint, thread-safe: starts bringing the accumulators that a splat of `path` at `filmPos`
    // adds to into this core's cache. The sorted pipeline's splats land in no pixel order, and
    // an atomic add to a line not in cache stalls the core until it arrives; prefetching a
    // chunk's splats before adding them overlaps those misses.
    void prefetch(uint path, vec2 filmPos) const;
    // After the iteration's last sample, before iterationAccumulators() and endIteration()
    // (which call it if needed): filters the sample sums into the iteration's sums.
    void finishSamples();
    // Adds the iteration to the whole render's sums (throws std::logic_error without a
    // beginIteration() since the last).
    void endIteration();
    // Drops the iteration in progress (a stopped render): the film is as after endIteration()
    // of the last whole iteration, and a new iteration has begun.
    void discardIteration();

    // The render so far: sum of weighted radiance / sum of weights, RGB, row-major.
    std::vector<float> image() const;
    // Rows y0 .. y1 - 1 of image() into rgb (width x (y1 - y0) x 3 floats).
    void imageRows(int y0, int y1, float* rgb) const;
    // The render of one half's samples alone (half 0 or 1).
    std::vector<float> halfImage(int half) const;
    // relMSE of image() estimated from the halves: per value (A - B)^2 / 4 / (d^2 + 0.01),
    // averaged; (A - B)^2 / 4 is an unbiased estimate of the variance of m = (A + B) / 2, and d
    // is m but where a glint inflates it (halfBufferTermRows).
    double halfBufferRelMse() const;
    // Its per-pixel terms, rows y0 .. y1 - 1 into rgb (width x (y1 - y0) x 3 floats): where the
    // noise is (--error-map). A pixel whose halves do not both hold samples yet reads 0.
    void errorRows(int y0, int y1, float* rgb) const;
    // The standard error of halfBufferRelMse() from its own terms: sqrt(2/3 sum_i P_i^2) / N,
    // P_i a pixel's three terms summed, N the terms (film.cpp says why). It matches the
    // estimate's spread over seeds to within a few per cent (HalfBufferEstimate tests). What it
    // cannot see is a bias of the estimate: an error that no pixel's samples have shown yet (a
    // bright light a few samples hit) is in no term.
    double halfBufferRelMseStandardError() const;
    // The same, or nothing while no pixel has samples in both halves (one iteration of one
    // sample per pixel): then there is no estimate yet, rather than an estimate of 0.
    std::optional<double> halfBufferRelMseEstimate() const;
    // Both in one pass over the image (each of the three above is one pass), and the same over
    // the subject: the pixels that hold noise, leaving out those whose halves agree to float
    // precision (a term below kFlatTerm: black, or a constant environment seen directly, which a
    // user does not look at for noise and which would dilute the mean in proportion to how much
    // of the frame they fill). The stop judges the subject (subjectError()).
    struct ErrorEstimate {
        std::optional<double> relMse;
        double standardError = 0.0;
        std::optional<double> subjectRelMse; // nothing while no pixel holds noise
        double subjectStandardError = 0.0;
        double subjectFraction = 0.0; // of the pixels with an estimate, those that hold noise
    };
    ErrorEstimate halfBufferError() const;
    // What the stop (--target-error and the default target) reads: the subject's relMSE, or the
    // whole image's while no pixel holds noise; nothing before any pixel has an estimate.
    std::optional<double> subjectRelMseEstimate() const;
    // A pixel whose three terms sum below this holds no noise: its halves agree to float
    // precision, (2^-24)^2 in relative error squared.
    static constexpr double kFlatTerm = 0x1p-48;
    // The last completed iteration alone (for per-iteration statistics), between endIteration()
    // and the next beginIteration() (throws std::logic_error otherwise).
    std::vector<float> lastIterationImage() const;

    // Adaptive sampling: `threshold` 0 turns it off (every pixel samples); tiles decide once
    // their pixels hold `minSamples` samples. Takes effect from the next iteration.
    static constexpr int kAdaptiveTile = 8;
    void setAdaptive(double threshold, int minSamples);
    // Adaptive sampling toward a target relMSE (with threshold 0): the tiles share the samples in
    // proportion to their noise, which reaches the target soonest (decideTargetTiles); 0 turns
    // it off. Takes effect from the next iteration.
    void setAdaptiveTarget(double relMse);
    // Whether this process takes pixel (x, y)'s samples in the coming iteration: the pixel's tile
    // is still sampling, and is in this process's share.
    bool sampling(int x, int y) const {
        return take_.empty() ||
               take_[size_t(y / kAdaptiveTile) * size_t(tilesX_) + size_t(x / kAdaptiveTile)];
    }
    // Whether any pixel (in any process's share) takes samples in the coming iteration.
    bool anySampling() const { return activeTiles_ > 0; }

    // Distributed rendering (host/render/ranks.h): this process takes the samples of share
    // `index` of `shares`: the k-th tile still sampling (row-major) goes to share k mod `shares`,
    // so that the shares stay even as adaptive sampling stops tiles. Takes effect from the next
    // iteration. The processes' iteration accumulators are then added together
    // (iterationAccumulators, setIterationAccumulators) before endIteration().
    void setShare(int index, int shares);
    // The fine levels' tiles the iteration reached (film_levels.h), a flag per level and tile;
    // summed over the processes, the tiles that iterationAccumulators() must carry.
    std::vector<std::int64_t> levelTilesReached();
    // The iteration's integer accumulators: 8 sums per pixel, then the iteration's non-finite
    // and saturated counts, then each level tile flagged in `tiles` (levelTilesReached()'s
    // layout; empty: this film's own), FilmLevels::kSlots sums each. (endIteration() counts the
    // samples of every tile still sampling, in any share: with shares, the accumulators are the
    // sum over the shares by then.)
    std::vector<std::int64_t> iterationAccumulators(const std::vector<std::int64_t>& tiles = {});
    // Replaces them, with their sum over the processes (the same layout and tiles).
    void setIterationAccumulators(const std::vector<std::int64_t>& values,
                                  const std::vector<std::int64_t>& tiles = {});
    // Camera samples each pixel took in whole iterations, and their total.
    std::vector<std::uint32_t> sampleCounts() const;
    std::uint64_t samplesTaken() const;

    // The film's whole state between iterations, exactly: what a checkpoint keeps.
    struct State {
        std::vector<Fixed> sums;            // 8 per pixel: (r, g, b, weight) x 2 halves
        std::vector<std::uint32_t> samples; // per pixel
        std::uint64_t nonFinite = 0, saturated = 0;
        int scaleExponent = 0, weightExponent = 0; // the fixed point: 2^e units per 1
        int levelBits = 0;                         // a fine level's step below the last
        // The fine levels that hold anything: 6 sums per pixel, (r, g, b) x 2 halves, in units of
        // 2^-(levelBits x level) of the home grid's.
        struct Level {
            int level = 0;
            std::vector<Fixed> sums;
        };
        std::vector<Level> levels;
    };
    // The image of a film state (as image() is of the film's): for merging partial renders.
    static std::vector<float> imageOf(const State& state);
    State state() const;
    // Restores a state() of a film of this size and fixed point (throws std::invalid_argument
    // otherwise).
    void restore(const State& state);

    std::uint64_t nonFiniteSamples() const { return nonFinite_.load(); }
    std::uint64_t saturatedSamples() const { return saturated_.load(); }
    double fixedPointScale() const { return scale_; }
    // The fine levels (film_levels.h): how many, the bits between two, and the bytes they hold.
    int fineLevels() const { return levelCount_; }
    int levelBits() const { return levelBits_; }
    size_t levelBytes() const { return iterLevels_.bytes() + renderLevels_.bytes(); }

  private:
    size_t pixels() const { return size_t(width_) * size_t(height_); }
    size_t tileOf(size_t pixel) const;
    // The whole render's sum k (0 .. 7) of pixel i, in fixed-point units.
    Fixed sumAt(size_t i, int k) const;
    void widenSums(); // adds the high halves, sign-extending every sum
    void addIterationToSums();
    int halfOf(uint sampleIndex) const; // by stratum or by stream (halves_)
    void decideTiles();                 // the tiles this process samples: adaptive mask and share
    void decideAdaptiveTiles();         // the adaptive mask, from the sums and counts
    // The mask toward adaptiveTarget_, from each tile's mean term (-1: not ready) and values.
    void decideTargetTiles(const std::vector<double>& mean, const std::vector<size_t>& count);
    // Pixel `pixel`'s eight sums in radiance and weight units.
    void pixelSums(size_t pixel, double* s) const;
    // The half-buffer relMSE's terms of rows y0 .. y1 - 1, three a pixel, into terms: per
    // channel (A - B)^2 / 4 / (d^2 + 0.01), d the pixel's value or, where its halves show a
    // spike that none of its neighbours explains, a value that spike cannot inflate
    // (termValue in film.cpp); kNoTerm for a pixel whose halves do not both hold samples yet.
    void halfBufferTermRows(int y0, int y1, double* terms) const;
    static constexpr double kNoTerm = -1.0;
    // fn(b0, b1, terms) for bands of rows b0 .. b1 - 1 of y0 .. y1 - 1, top to bottom, 64 rows
    // at most (from y0 = 0, whole tiles): the terms of every pixel, a band's at a time.
    template <typename Fn> void forHalfBufferTerms(int y0, int y1, const Fn& fn) const;
    // The estimate's running sums over a band's terms (n pixels), in pixel order.
    struct ErrorSums {
        double total = 0.0, squares = 0.0;
        size_t count = 0;
        double subjectTotal = 0.0, subjectSquares = 0.0; // over the pixels that hold noise
        size_t subjectCount = 0;
        void add(const double* terms, size_t n);
        ErrorEstimate estimate() const;
    };
    float weight1D(float d) const;
    // fn(x, y, w) for each pixel of the filter's footprint around filmPos, w > 0 its weight.
    template <typename Fn> void forFootprint(vec2 filmPos, const Fn& fn) const;
    void filtered(vec2 filmPos, int half, vec3 radiance, float weight, uint key);
    void add(int px, int py, int half, vec3 value, float weight, uint key);
    // Whether v (home units) is below the home grid's precision, 0 < |v| < 2^24: then it is
    // rounded with u into its fine level, at channel c of pixel's half (or dropped below the
    // finest, under the smallest float).
    bool addFine(size_t pixel, int half, int c, double v, uint u);
    static constexpr double kHomeFloor = 0x1p24;
    // v (fixed-point units) clamped (counted) and rounded stochastically with u: E = v.
    std::int64_t quantize(double v, uint u);
    // Sample sums (wide filters): the contribution into path's sum; the sums of rows [y0, y1)
    // filtered (not thread-safe: finishSamples() keeps the threads' footprints apart).
    void addToSample(uint path, vec3 radiance);
    // lanes[0, count) rounded (roundFootprint, host/simd/film_rounding.h) into adds, the
    // padding to whole vectors adding nothing; the clamped values counted as saturated. A
    // channel below the home grid's precision goes to its fine level instead (addFine, into the
    // lane's half, halves[k]) and adds nothing here.
    void roundLanes(FootprintLanes& lanes, size_t count, const int* halves, FootprintAdds& adds);
    void filterSamples(int y0, int y1);

    int width_, height_;
    uint samplesPerIteration_;
    Halves halves_;
    Filter filter_;
    float gaussK_ = 0.0f, gaussTail_ = 0.0f; // the Gaussian's exponent factor and its value at r
    double scale_;                           // radiance units -> fixed-point units
    double weightScale_;                     // filter weight -> fixed-point units
    double maxAdd_;                          // the clamp of one add, in fixed-point units
    // (r, g, b, weight) x 2 halves: one cache line per pixel, so that a splat is one line.
    struct alignas(64) PixelSums {
        std::atomic<std::int64_t> v[8];
    };
    struct FreeSums {
        void operator()(PixelSums* p) const;
    };
    using Sums = std::unique_ptr<PixelSums[], FreeSums>;
    // Allocated with every sum 0, in huge pages where the system gives them (a 16-Mpixel film's
    // first touch is then 2 thousand page faults rather than a quarter million), zeroed in
    // parallel.
    static Sums zeroedSums(size_t pixels);
    Sums acc_;             // this iteration; null until it begins
    bool open_ = false;    // an iteration has begun and not ended
    bool accZero_ = false; // acc_ holds only zeros
    // The whole render's sums, in fixed-point units: the low 64 bits (null: all 0), and the high
    // 64 bits (null while every sum fits in 64 bits, the low word then sign-extended).
    Sums sumLo_;
    std::unique_ptr<std::int64_t[]> sumHi_;
    std::uint64_t sumBound_ = 0; // while sumHi_ is null: the largest |sum|
    // The last ended iteration's sums (acc_, or sumLo_ when it was the first); null once the
    // next iteration begins.
    const PixelSums* lastIteration_ = nullptr;
    std::atomic<std::uint64_t> nonFinite_{0}, saturated_{0};
    double adaptiveThreshold_ = 0.0;
    double adaptiveTarget_ = 0.0;
    int adaptiveMinSamples_ = 0;
    int tilesX_ = 0, tilesY_ = 0;
    // Camera samples each pixel of a tile took in whole iterations: all of a tile's pixels
    // sample together (adaptive sampling and the shares decide by tile), so one count a tile.
    std::vector<std::uint32_t> tileSamples_;
    // halfBufferError() of the sums as they are, where the adaptive decision that followed their
    // last change computed it in its own pass over the terms; empty otherwise.
    std::optional<ErrorEstimate> errorOfDecision_;
    std::vector<std::uint8_t> active_; // per tile; empty: adaptive sampling off
    size_t activeTiles_ = 1;
    int share_ = 0, shares_ = 1;
    std::vector<std::uint8_t> take_; // per tile: active and in this share; empty: every tile
    // The iteration's sample sums (wide filters only; null until the first iteration begins):
    // one per path id, and where the sample lies, in home units. A path's sum is only ever
    // changed by one thread at a time, and its contributions come in the same order on every
    // backend, so each add is a load and a store, and the double sum is the same every time.
    struct SampleSum {
        std::atomic<double> rgb[3];
        float x, y;
    };
    std::unique_ptr<SampleSum[]> samples_;
    bool samplesPending_ = false;     // the iteration's sample sums are not yet filtered
    std::atomic<uint> sampleBase_{0}; // the iteration's first sample index
    // The fine levels: their number and step, the iteration's (allocated as reached) and the
    // render's, and the last ended iteration's (iterLevels_ or, after the first, renderLevels_).
    int levelCount_ = 0, levelBits_ = 0;
    std::vector<double> levelScale_; // 2^(bits x level): home units to the level's
    FilmLevels iterLevels_, renderLevels_;
    const FilmLevels* lastLevels_ = nullptr;
    // The fine-level sums of pixel i's rgb channels (k = 0, 1, 2, 4, 5, 6 of pixelSums), in
    // home units, added into s.
    void addLevelSums(const FilmLevels& levels, size_t i, double* s) const;
    // Pixel i's tile and the first of its six slots there (FilmLevels: (r, g, b) x 2 halves).
    std::pair<size_t, size_t> levelSlot(size_t i) const {
        const size_t x = i % size_t(width_), y = i / size_t(width_);
        return {y / kAdaptiveTile * size_t(tilesX_) + x / kAdaptiveTile,
                ((y % kAdaptiveTile) * kAdaptiveTile + x % kAdaptiveTile) * 6};
    }
    // nonFinite_ and saturated_ when the iteration began.
    std::uint64_t nonFiniteBefore_ = 0, saturatedBefore_ = 0;
};

} // namespace spw
