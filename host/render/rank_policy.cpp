#include "host/render/rank_policy.h"

#include <algorithm>
#include <string>
#include <vector>

namespace spw {
namespace {

// --stats of a distributed render, on rank 0: every rank's own stats (`all`, JSON in rank
// order) as `ranks`, and the traffic (rays, spill, textures) summed over them.
void addRanksToStats(const std::vector<std::string>& all, RenderStats& stats) {
    nlohmann::json perRank = nlohmann::json::array();
    std::uint64_t rays[3] = {0, 0, 0};
    nlohmann::json totals = nlohmann::json::object();
    const char* summed[] = {"batches_processed", "batches_queued", "batches_spilled",
                            "bytes_spilled_written", "bytes_spilled_read"};
    for (size_t r = 0; r < all.size(); ++r) {
        const nlohmann::json j = nlohmann::json::parse(all[r]);
        nlohmann::json entry = {{"rank", r},
                                {"host", j.value("host", "")},
                                {"threads", j["threads"]},
                                {"wall_seconds", j["wall_seconds"]},
                                {"render_seconds", j["render_seconds"]},
                                {"reduce_seconds", j["stage_seconds"].value("reduce", 0.0)},
                                {"agree_seconds", j["stage_seconds"].value("agree", 0.0)},
                                {"rays", j["rays"]}};
        rays[0] += j["rays"]["camera"].get<std::uint64_t>();
        rays[1] += j["rays"]["bounce"].get<std::uint64_t>();
        rays[2] += j["rays"]["shadow"].get<std::uint64_t>();
        for (const char* key : summed)
            if (j.contains(key)) {
                entry[key] = j[key];
                totals[key] = totals.value(key, std::uint64_t(0)) + j[key].get<std::uint64_t>();
            }
        if (j.contains("peak_ray_bytes_in_ram"))
            entry["peak_ray_bytes_in_ram"] = j["peak_ray_bytes_in_ram"];
        if (j.contains("textures")) {
            entry["textures"] = j["textures"];
            // The counters summed; the cache's peak is the largest rank's.
            if (!totals.contains("textures")) totals["textures"] = nlohmann::json::object();
            nlohmann::json& t = totals["textures"];
            for (const char* key : {"lookups", "tiles_read", "bytes_read", "files_opened",
                                    "files_reopened", "cache_misses"})
                t[key] = t.value(key, std::uint64_t(0)) + j["textures"][key].get<std::uint64_t>();
            t["peak_cache_bytes"] =
                std::max(t.value("peak_cache_bytes", std::uint64_t(0)),
                         j["textures"]["peak_cache_bytes"].get<std::uint64_t>());
        }
        perRank.push_back(entry);
    }
    stats.cameraRays = rays[0];
    stats.bounceRays = rays[1];
    stats.shadowRays = rays[2];
    if (totals.contains("textures")) {
        nlohmann::json& t = totals["textures"];
        const double all = double(rays[0] + rays[1] + rays[2]);
        for (const char* key : {"lookups", "tiles_read", "bytes_read"})
            t["per_ray"][key] = all > 0 ? t[key].get<double>() / all : 0.0;
    }
    for (auto it = totals.begin(); it != totals.end(); ++it)
        stats.extra[it.key()] = it.value();
    stats.extra["ranks"] = perRank;
}

} // namespace

Ranks::Agreement RankSync::agreeBefore(bool stop, bool timeUp, StageTimes& stages) {
    StageTimer t(stages, "agree"); // waiting for the slowest rank, mostly
    return ranks_.agree(false, stop, timeUp);
}

bool RankSync::agreeWhole(bool whole, StageTimes& stages) {
    StageTimer t(stages, "agree");
    return !ranks_.agree(false, !whole, false).stop;
}

void RankSync::reduce(Film& film, StageTimes& stages) {
    // Every rank's share of the iteration, added exactly: the same film on every rank.
    StageTimer t(stages, "reduce");
    std::vector<std::int64_t> sums = film.iterationAccumulators();
    ranks_.sum(sums);
    film.setIterationAccumulators(sums);
}

void RankSync::finish(RenderStats& stats, double wallSeconds) {
    stats.wallSeconds = wallSeconds;
    nlohmann::json mine = stats.toJson();
    mine["host"] = ranks_.host();
    const std::string text = mine.dump();
    ranks_.agree(false, false, false); // a rank that failed since the last one says so here
    const std::vector<std::string> all = ranks_.gather(text);
    ranks_.finish(); // the last collective: rank 0 writes the outputs alone
    if (writes()) addRanksToStats(all, stats);
}

std::unique_ptr<RankPolicy> rankPolicy(Ranks* ranks) {
    if (!ranks) return std::make_unique<SingleProcess>();
    return std::make_unique<RankSync>(*ranks);
}

} // namespace spw
