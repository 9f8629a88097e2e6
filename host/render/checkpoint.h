// Checkpoints: a render's exact state between iterations, so that a stopped render can resume
// and finish with the image, bit for bit, that it would have made uninterrupted.
//
// The checkpoint is one OpenEXR file that any image viewer opens: its R, G, B channels are the
// image so far (float), and 32 more channels, state.0.0 .. state.7.3 (uint32), hold the film's
// eight 128-bit integer sums per pixel bit for bit (each as four 32-bit words, the most
// significant first: EXR has no wider integer channel type, and float channels would round
// the sums), and one more,
// state.samples (uint32), the camera samples each pixel took (adaptive sampling reads them).
// Metadata (spillway:*) holds the rest: iterations done, render seconds, the film's counters, and
// what must match for a resume (the key below). One file rather than an image and a state file
// beside it: nothing can pair an image with another render's state, and one rename writes it
// atomically.
#pragma once

#include "host/backend/render_config.h"
#include "host/image/film.h"
#include "host/scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace spw {

// What decides the image besides the number of iterations: a checkpoint resumes only where all
// of it matches. The backend, threads, batch sizes, budgets and sort settings are not in it:
// they change how fast, not what (compact rays aside, which is why the ray format is).
struct CheckpointKey {
    std::string version;               // Spillway's
    std::uint64_t sceneHash = 0;       // sceneHash()
    std::uint64_t environmentHash = 0; // environmentHash()
    std::uint32_t seed = 0;
    int width = 0, height = 0;
    int sampleBase = 0;           // samples per pixel and iteration = sampleBase^2
    std::string rayFormat;        // compact | full
    std::string textureFilter;    // cone | finest
    std::uint32_t strategy = 0;   // light / BSDF sampling
    std::string sampler;          // Independent | Grid | Stratified | Sobol
    double adaptiveThreshold = 0; // 0: off
    int adaptiveMinSamples = 0;
    double adaptiveTarget =
        0; // the relMSE the tiles share samples toward (adaptiveTarget); 0: none
};

struct Checkpoint {
    CheckpointKey key;
    int iterations = 0;       // completed, from firstIteration on
    int firstIteration = 0;   // 0, or where a partial render (--samples A:B) began
    int totalIterations = 0;  // of the whole render (partials: what merge must cover)
    double renderSeconds = 0; // spent in them
    Film::State film;
};

// FNV-1a over 64-bit words: the digests of a render's identity.
struct Fnv {
    std::uint64_t h = 0xcbf29ce484222325ull;
    void bytes(const void* data, size_t n);
    void text(const std::string& s) {
        const std::uint64_t n = s.size();
        bytes(&n, sizeof n);
        bytes(s.data(), s.size());
    }
    template <class T> void array(const std::vector<T>& v) {
        const std::uint64_t n = v.size();
        bytes(&n, sizeof n);
        bytes(v.data(), v.size() * sizeof(T));
    }
    template <class T> Fnv& value(const T& v) {
        bytes(&v, sizeof v);
        return *this;
    }
};

// The scene as rendered: its file's text, every mesh's vertices and triangles, and every byte of
// every image texture (a texture swapped for another of the same size and time is found; hashing
// reads each file once, about 1 s per GB from the page cache).
std::uint64_t sceneHash(const Scene& scene);
// The environment as rendered: its radiance and every texel of its map (0 without one).
std::uint64_t environmentHash(const Scene& scene);

// The relMSE toward which a render's tiles share its samples by their noise
// (Film::setAdaptiveTarget), or 0 where every pixel samples alike: --target-error without
// --uniform, but not in a partial render (whose samples are the whole render's range, not its
// own to share) nor under an adaptive threshold.
double adaptiveTarget(const Scene& scene, const RenderConfig& config);

// The key of a render of `scene` with `config` (sampleBase from the sampling plan).
CheckpointKey checkpointKey(const Scene& scene, const RenderConfig& config, int sampleBase);

// Written whole or not at all (output_file.h). Throws std::runtime_error naming the path.
void writeCheckpoint(const std::string& path, const Checkpoint& checkpoint,
                     const std::vector<float>& image);
// Throws std::runtime_error naming the path when it is not a Spillway checkpoint.
Checkpoint readCheckpoint(const std::string& path);
// Adds partial renders' checkpoints (--samples A:B --partial), each with the file it came from,
// into the whole render's: throws std::invalid_argument naming the files when they are of
// different renders, overlap, or leave samples out. The film's sums are integers, so the result
// is the uninterrupted render's, bit for bit, whatever the partials and their order.
Checkpoint mergePartials(const std::vector<std::pair<std::string, Checkpoint>>& partials);

// "" when `found` may resume a render whose key is `expected`; else what differs, for the user.
std::string checkpointMismatch(const CheckpointKey& expected, const CheckpointKey& found);

} // namespace spw
