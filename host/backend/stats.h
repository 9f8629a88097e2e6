// What a render reports with --stats: its size, its traffic and where its time went.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace spw {

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

struct RenderStats {
    std::string backend;
    std::string device;
    int width = 0, height = 0, spp = 0, iterations = 0, threads = 0;
    double wallSeconds = 0.0;
    std::atomic<std::uint64_t> cameraRays{0}, bounceRays{0}, shadowRays{0};
    std::uint64_t nonFiniteSamples = 0, saturatedSamples = 0;
    StageTimes stages;
    nlohmann::json extra = nlohmann::json::object(); // backend-specific counters

    nlohmann::json toJson() const;
};

} // namespace spw
