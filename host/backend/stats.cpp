#include "host/backend/stats.h"

#include <sys/resource.h>

#include <algorithm>

namespace spw {

double peakResidentMiB() {
    rusage usage{};
    if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
    return double(usage.ru_maxrss) / 1024.0; // Linux: KiB
}

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

void SpillCounters::merge(const SpillCounters& o) {
    batchesProcessed += o.batchesProcessed;
    batchesQueued += o.batchesQueued;
    batchesSpilled += o.batchesSpilled;
    bytesWritten += o.bytesWritten;
    bytesRead += o.bytesRead;
}

bool SpillCounters::operator==(const SpillCounters& o) const {
    return batchesProcessed == o.batchesProcessed && batchesQueued == o.batchesQueued &&
           batchesSpilled == o.batchesSpilled && bytesWritten == o.bytesWritten &&
           bytesRead == o.bytesRead && peakRayBytesInRam == o.peakRayBytesInRam;
}

void TextureCounters::merge(const TextureCounters& o) {
    lookups += o.lookups;
    tilesRead += o.tilesRead;
    bytesRead += o.bytesRead;
    filesOpened += o.filesOpened;
    filesReopened += o.filesReopened;
    cacheMisses += o.cacheMisses;
    peakCacheBytes = std::max(peakCacheBytes, o.peakCacheBytes);
    tiledCopies += o.tiledCopies;
    tiledCopyBytes += o.tiledCopyBytes;
}

bool TextureCounters::operator==(const TextureCounters& o) const {
    return lookups == o.lookups && tilesRead == o.tilesRead && bytesRead == o.bytesRead &&
           filesOpened == o.filesOpened && filesReopened == o.filesReopened &&
           cacheMisses == o.cacheMisses && peakCacheBytes == o.peakCacheBytes &&
           tiledCopies == o.tiledCopies && tiledCopyBytes == o.tiledCopyBytes;
}

namespace {

// The counters' JSON keys, each written and read here alone.
void writeSpill(const SpillCounters& c, nlohmann::json& j) {
    j["batches_processed"] = c.batchesProcessed;
    j["batches_queued"] = c.batchesQueued;
    j["batches_spilled"] = c.batchesSpilled;
    j["bytes_spilled_written"] = c.bytesWritten;
    j["bytes_spilled_read"] = c.bytesRead;
    j["peak_ray_bytes_in_ram"] = c.peakRayBytesInRam;
}

SpillCounters readSpill(const nlohmann::json& j) {
    SpillCounters c;
    c.batchesProcessed = j.at("batches_processed").get<std::uint64_t>();
    c.batchesQueued = j.at("batches_queued").get<std::uint64_t>();
    c.batchesSpilled = j.at("batches_spilled").get<std::uint64_t>();
    c.bytesWritten = j.at("bytes_spilled_written").get<std::uint64_t>();
    c.bytesRead = j.at("bytes_spilled_read").get<std::uint64_t>();
    c.peakRayBytesInRam = j.at("peak_ray_bytes_in_ram").get<std::uint64_t>();
    return c;
}

// --stats' `textures`: the texture system's counters, and the traffic per traced ray.
nlohmann::json texturesJson(const TextureCounters& t, std::uint64_t rays) {
    auto perRay = [&](std::uint64_t n) { return rays > 0 ? double(n) / double(rays) : 0.0; };
    return {{"lookups", t.lookups},
            {"tiles_read", t.tilesRead},
            {"bytes_read", t.bytesRead},
            {"files_opened", t.filesOpened},
            {"files_reopened", t.filesReopened},
            {"cache_misses", t.cacheMisses},
            {"peak_cache_bytes", t.peakCacheBytes},
            {"tiled_copies", t.tiledCopies},
            {"tiled_copy_bytes", t.tiledCopyBytes},
            {"per_ray",
             {{"lookups", perRay(t.lookups)},
              {"tiles_read", perRay(t.tilesRead)},
              {"bytes_read", perRay(t.bytesRead)}}}};
}

TextureCounters readTextures(const nlohmann::json& j) {
    TextureCounters t;
    t.lookups = j.at("lookups").get<std::uint64_t>();
    t.tilesRead = j.at("tiles_read").get<std::uint64_t>();
    t.bytesRead = j.at("bytes_read").get<std::uint64_t>();
    t.filesOpened = j.at("files_opened").get<std::uint64_t>();
    t.filesReopened = j.at("files_reopened").get<std::uint64_t>();
    t.cacheMisses = j.at("cache_misses").get<std::uint64_t>();
    t.peakCacheBytes = j.at("peak_cache_bytes").get<std::uint64_t>();
    t.tiledCopies = j.value("tiled_copies", std::uint64_t(0));
    t.tiledCopyBytes = j.value("tiled_copy_bytes", std::uint64_t(0));
    return t;
}

} // namespace

void RenderStats::readCounters(const nlohmann::json& j) {
    cameraRays = j.at("rays").at("camera").get<std::uint64_t>();
    bounceRays = j.at("rays").at("bounce").get<std::uint64_t>();
    shadowRays = j.at("rays").at("shadow").get<std::uint64_t>();
    spill.reset();
    textures.reset();
    if (j.contains("batches_processed")) spill = readSpill(j);
    if (j.contains("textures")) textures = readTextures(j.at("textures"));
}

void RenderStats::mergeCounters(const RenderStats& o) {
    cameraRays += o.cameraRays;
    bounceRays += o.bounceRays;
    shadowRays += o.shadowRays;
    if (o.spill) {
        if (!spill) spill = SpillCounters{};
        spill->merge(*o.spill);
    }
    if (o.textures) {
        if (!textures) textures = TextureCounters{};
        textures->merge(*o.textures);
    }
}

nlohmann::json RenderStats::countersJson() const {
    const std::uint64_t total = cameraRays + bounceRays + shadowRays;
    nlohmann::json j = {{"rays",
                         {{"camera", cameraRays.load()},
                          {"bounce", bounceRays.load()},
                          {"shadow", shadowRays.load()},
                          {"total", total}}}};
    if (spill) writeSpill(*spill, j);
    if (textures) j["textures"] = texturesJson(*textures, total);
    return j;
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
    const std::uint64_t total = cameraRays + bounceRays + shadowRays;
    j.update(countersJson());
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
