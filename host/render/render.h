// One render, start to finish: builds what the scene needs, picks the backend, runs the
// iterations into the film and fills in the stats. The CLI and the tests both call this.
#pragma once

#include "host/backend/render_config.h"
#include "host/backend/stats.h"
#include "host/image/aov_film.h"
#include "host/image/film.h"
#include "host/render/checkpoint.h"
#include "host/render/ranks.h"
#include "host/scene/scene.h"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace spw {

struct RenderResult {
    std::unique_ptr<Film> film;
    RenderStats stats;
    std::unique_ptr<AovFilm> aovs; // with RenderConfig::aovs, the passes
};

// Called after every iteration with (iterations done, iterations in all, the film).
using IterationCallback = std::function<void(int, int, const Film&)>;

struct IterationInfo {
    int done = 0, total = 0;  // iterations
    int spp = 0;              // samples per pixel so far
    double renderSeconds = 0; // time in the iterations so far, callbacks excluded
};
using ProgressCallback = std::function<void(const IterationInfo&, const Film&)>;

// The effective sampling after --spp: samples per pixel and iteration, and iterations.
struct SamplingPlan {
    int sampleBase;
    int iterations;
};
// `resumedBase`: the sample base of the checkpoint a render resumes (0: none), kept where it
// divides the samples asked for.
SamplingPlan planSampling(const ImageSettings& image, std::optional<int> spp, int resumedBase = 0);

// Why a checkpoint (found) cannot be resumed by a render keyed `expected`, or "". Where the only
// cause is an --spp the scene's n x n pattern does not divide (this render would take one sample
// per pass), it says so, instead of naming a sample base the user never set.
std::string resumeProblem(const CheckpointKey& expected, const CheckpointKey& found,
                          const ImageSettings& image, std::optional<int> spp);

// What is wrong with a partial render's sample range A:B (--samples), or "": it must lie within
// the render's spp, on iteration boundaries (the message names them), without adaptive
// sampling.
std::string partialRenderProblem(const Scene& scene, const RenderConfig& config,
                                 const SamplingPlan& plan);

// Checkpointing a render (host/render/checkpoint.h): where, how often, and where to start.
struct CheckpointOptions {
    std::string path;                   // empty: no checkpoint
    double intervalSeconds = 0;         // also every this many render seconds (0: only at the end)
    const Checkpoint* resume = nullptr; // continue from it
    // This render's key when the caller has it already (checkpointKey() hashes every mesh).
    std::optional<CheckpointKey> key;
};

// Throws std::invalid_argument for a bad configuration (unknown backend) and
// std::runtime_error for a failure while rendering.
std::unique_ptr<RenderResult> render(const Scene& scene, const RenderConfig& config,
                                     const IterationCallback& onIteration = {});
// The same, reporting render time too; stops early at config.timeLimitSeconds.
// With `checkpoints`, resumes and writes checkpoints: every interval, and at the end however the
// render stopped (its completed iterations).
// With `ranks`, renders this rank's share of a distributed render (host/render/ranks.h): every
// rank returns the whole film; only rank 0 writes checkpoints, and its stats hold every rank's
// (`ranks`) and their totals. A failure on any rank throws on every rank.
std::unique_ptr<RenderResult> renderWithProgress(const Scene& scene, const RenderConfig& config,
                                                 const ProgressCallback& onIteration,
                                                 const CheckpointOptions& checkpoints = {},
                                                 Ranks* ranks = nullptr);

} // namespace spw
