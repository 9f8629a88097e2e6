// What a render reports with --stats: its size, its traffic and where its time went.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace spw {

// The process's peak resident memory so far, in MiB (getrusage's ru_maxrss).
double peakResidentMiB();

// Seconds per pipeline stage, in the order stages first report. Thread-safe.
class StageTimes {
  public:
    void add(const std::string& stage, double seconds);
    std::vector<std::pair<std::string, double>> snapshot() const;
    double get(const std::string& stage) const;

  private:
    mutable std::mutex mutex_;
    std::vector<std::pair<std::string, double>> stages_;
};

// Times a scope into a StageTimes entry.
class StageTimer {
  public:
    StageTimer(StageTimes& times, const char* stage)
        : times_(times), stage_(stage), start_(std::chrono::steady_clock::now()) {}
    ~StageTimer() {
        times_.add(
            stage_,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
    }
    StageTimer(const StageTimer&) = delete;
    StageTimer& operator=(const StageTimer&) = delete;

  private:
    StageTimes& times_;
    const char* stage_;
    std::chrono::steady_clock::time_point start_;
};

// The traffic counters that a distributed render adds up over its ranks, typed, each with its
// merge rule. RenderStats::toJson writes them and RenderStats::readCounters reads them back, both
// in stats.cpp, so that a key renamed in one is renamed in the other and no counter can drop out
// of the ranks' totals.
struct SpillCounters {
    std::uint64_t batchesProcessed = 0, batchesQueued = 0, batchesSpilled = 0;
    std::uint64_t bytesWritten = 0, bytesRead = 0; // spill file traffic
    std::uint64_t peakRayBytesInRam = 0;           // this process's own: never merged
    void merge(const SpillCounters& o);            // sums
    bool operator==(const SpillCounters& o) const;
};

struct TextureCounters {
    std::uint64_t lookups = 0, tilesRead = 0, bytesRead = 0, filesOpened = 0, filesReopened = 0,
                  cacheMisses = 0;
    std::uint64_t peakCacheBytes = 0;
    std::uint64_t tiledCopies = 0, tiledCopyBytes = 0; // textures/tiled_copy.h
    void merge(const TextureCounters& o);              // sums; the cache's peak is the largest
    bool operator==(const TextureCounters& o) const;
};

struct RenderStats {
    std::string backend;
    std::string device;
    int width = 0, height = 0, spp = 0, iterations = 0, threads = 0;
    double wallSeconds = 0.0;
    std::atomic<std::uint64_t> cameraRays{0}, bounceRays{0}, shadowRays{0};
    std::uint64_t nonFiniteSamples = 0, saturatedSamples = 0;
    StageTimes stages;
    std::optional<SpillCounters> spill;              // the sorted pipeline's batches and spill
    std::optional<TextureCounters> textures;         // where image textures are read
    nlohmann::json extra = nlohmann::json::object(); // what each part reports of its decisions

    nlohmann::json toJson() const;
    // The rays and the counters alone, as toJson writes them.
    nlohmann::json countersJson() const;
    // The rays and counters of `j` (what toJson wrote), replacing this object's.
    void readCounters(const nlohmann::json& j);
    // Adds `o`'s rays and counters to this object's.
    void mergeCounters(const RenderStats& o);
};

} // namespace spw
