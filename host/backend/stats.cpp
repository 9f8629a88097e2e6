#include "host/backend/stats.h"

namespace spw {

void StageTimes::add(const std::string& stage, double seconds) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& s : stages_)
        if (s.first == stage) {
            s.second += seconds;
            return;
        }
    stages_.emplace_back(stage, seconds);
}

std::vector<std::pair<std::string, double>> StageTimes::snapshot() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stages_;
}

double StageTimes::get(const std::string& stage) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& s : stages_)
        if (s.first == stage) return s.second;
    return 0.0;
}

nlohmann::json RenderStats::toJson() const {
    nlohmann::json j = nlohmann::json::object();
    j["backend"] = backend;
    j["device"] = device;
    j["width"] = width;
    j["height"] = height;
    j["spp"] = spp;
    j["iterations"] = iterations;
    j["threads"] = threads;
    j["wall_seconds"] = wallSeconds;
    std::uint64_t total = cameraRays + bounceRays + shadowRays;
    j["rays"] = {{"camera", cameraRays.load()},
                 {"bounce", bounceRays.load()},
                 {"shadow", shadowRays.load()},
                 {"total", total}};
    j["rays_per_second"] = wallSeconds > 0 ? double(total) / wallSeconds : 0.0;
    j["non_finite_samples"] = nonFiniteSamples;
    j["saturated_samples"] = saturatedSamples;
    nlohmann::json st = nlohmann::json::object();
    for (const auto& [name, secs] : stages.snapshot())
        st[name] = secs;
    j["stage_seconds"] = st;
    for (auto it = extra.begin(); it != extra.end(); ++it)
        j[it.key()] = it.value();
    return j;
}

} // namespace spw
