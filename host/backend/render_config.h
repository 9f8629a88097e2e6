// Everything about a render that is not the scene: passed explicitly, never global. A leaf:
// it includes nothing of the renderer, so that every part of it (pipeline, vk, the backends)
// may read its own knobs here without reaching up. The names each option takes on the command
// line are parsed in render_config.cpp, in one place.
#pragma once

#include "shared/types.h"

#include <atomic>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace spw {

// A render refused before any work because its inputs do not fit together (a checkpoint or a
// partial range of another render, MPI ranks that would render different things): bad input,
// exit 2, as a usage or scene error is.
class RenderRefused : public std::invalid_argument {
  public:
    using std::invalid_argument::invalid_argument;
};

// Which renderer: the sorted pipeline shading with Vulkan or C++, or the depth-first reference.
// Auto: a real GPU where one is usable, else cpu (vk::chooseAutoDevice).
enum class BackendKind { Auto, Vulkan, Cpu, Reference };
BackendKind parseBackend(const std::string& name); // auto | vulkan | cpu | reference
const char* backendName(BackendKind kind);

// How rays wait between bounces (host/pipeline/ray_record.h): 34-byte compact records, or
// 50-byte full ones that keep every bit.
enum class RayFormat { Compact, Full };
RayFormat parseRayFormat(const std::string& name); // compact | full
const char* rayFormatName(RayFormat format);

// How a batch's rays are ordered before traversal (host/pipeline/ray_sort.h).
enum class RaySortMode { Auto, Morton, Median, Off };
RaySortMode parseRaySortMode(const std::string& name); // auto | morton | median | off
const char* raySortName(RaySortMode mode);

// How hits are shaded. Sorted: hits sorted by (shader, object, texture order), one homogeneous
// dispatch per shader range, each with its model's own kernel. Megakernel (the ablation): the
// hits stay unsorted and one uber-shader switches on the model per hit. Unsorted hits (also
// --hit-sort off) always take the megakernel: they have no homogeneous ranges.
enum class ShadingMode { Sorted, Megakernel };
ShadingMode
parseShadingMode(const std::string& name); // "sorted" | "megakernel"; throws invalid_argument
const char* shadingModeName(ShadingMode mode);

// Whether hits are sorted by (shader, object, texture order) before shading. Auto: where it
// pays: always for Vulkan (one homogeneous dispatch per shader range is that engine's point), and
// for the cpu engine only on scenes with image textures (coherent tile reads); on other scenes the
// cpu engine shades the same function whatever the order, and the sort measured a pure cost
// (0.25 s of a 4 s render on the Cornell box).
enum class HitSortMode { Auto, On, Off };
HitSortMode parseHitSortMode(const std::string& name); // "auto" | "on" | "off"

// Which MIP levels image-texture lookups read. Cone (the default): the level the ray cone's
// footprint needs (shared/cone.h), trilinear. Finest (the ablation): always the finest level,
// as a renderer without filtering does, and as the thesis' experiment measured.
enum class TextureFilter { Cone, Finest };
TextureFilter parseTextureFilter(const std::string& name); // "cone" | "finest"

// What the scene's settings do not say about the pipeline: the ablation knobs.
struct PipelineConfig {
    RayFormat rayFormat = RayFormat::Compact;
    RaySortMode raySort = RaySortMode::Auto;
    HitSortMode hitSort = HitSortMode::Auto;
    ShadingMode shading = ShadingMode::Sorted;
    // Hits may be sorted only for sorted shading (the renderer applies the auto rule).
    bool sortsHits() const { return hitSort != HitSortMode::Off && shading == ShadingMode::Sorted; }
    std::string spillDir; // empty: the system temp folder
    // The cpu engine's per-hit stages fused chunk by chunk (stages.h: shadeFused); false runs
    // them one whole batch after another, as the Vulkan engine must (the ablation).
    bool fuseStages = true;
    // The cpu engine shades the hits of every model with a SIMD twin (kWideTwins, simd_shading.h)
    // SIMD-wide; false: shadeSurface() hit by hit (the ablation; the image is the same to the bit).
    bool simdShading = true;
};

// Every parse* throws std::invalid_argument naming the value and the choices.

// The Vulkan backend's knobs (--device, and what the tests switch on).
struct VulkanConfig {
    std::string device;                // --device: an index into `spillway devices`, or part of a
                                       // device name; empty: the first usable device
    bool validation = false;           // Khronos validation layer + a messenger counting messages
                                       // (also on when SPILLWAY_VK_VALIDATION=1)
    bool forceStaging = false;         // staging copies even where memory is device-local and
                                       // host-visible (tests the path discrete GPUs take)
    std::uint32_t maxGroupsX = 0;      // tests: cap on workgroups per dimension (0: the device's)
    std::uint64_t maxBindingBytes = 0; // tests: cap on a bound buffer range (0: the device's)
};

constexpr int kStopByWindow = -1; // RenderConfig::stop's value when the preview window closed
// RenderConfig::stop's value when the preview's display went away: a stop like SIGHUP's.
constexpr int kStopByLostDisplay = -2;

// The scene's settings (seed, budgets, adaptive sampling) are not here: the CLI's overrides of
// them are applied to the scene once it is loaded (host/scene/settings_table.h).
struct RenderConfig {
    // The library's default stays cpu so that callers that do not ask for a device never
    // initialise Vulkan; the CLI's default is auto.
    BackendKind backend = BackendKind::Cpu;
    int threads = 0;                        // 0: every core
    std::optional<int> spp;                 // overrides sample base and iterations
    uint strategy = kStrategyMis;           // light/BSDF sampling ablation (tests, benchmarks)
    PipelineConfig pipeline;                // the sorted backends' knobs
    VulkanConfig vulkan;                    // the vulkan backend's knobs
    std::optional<double> timeLimitSeconds; // stop after the iteration that crosses it
    // Stop after the first iteration whose half-buffer relMSE estimate (Film::halfBufferRelMse)
    // is at or below this.
    std::optional<double> targetError;
    // With targetError and no adaptive threshold: the tiles share the samples by their noise
    // toward it (Film::setAdaptiveTarget); false: every pixel samples alike.
    bool adaptiveToTarget = true;
    // Nonzero: stop at the next batch (or tile) boundary and discard the iteration in progress;
    // the render keeps every completed iteration. Set from a signal handler (the CLI's).
    // kStopByWindow when the preview window was closed, kStopByLostDisplay when its display went
    // away, else the signal's number.
    const std::atomic<int>* stop = nullptr;
    // A partial render: only samples [first, second) of the spp (iteration boundaries).
    std::optional<std::pair<int, int>> sampleRange;
    TextureFilter textureFilter = TextureFilter::Cone;
    // Render passes beside the image (host/image/aov_film.h's kAov* bits; 0: none).
    unsigned aovs = 0;
};

} // namespace spw
