#include "host/render/rank_policy.h"

#include "host/backend/render_config.h"

#include <algorithm>
#include <string>
#include <vector>

namespace spw {
namespace {

// --stats of a distributed render, on rank 0: every rank's own stats (`all`, JSON in rank
// order) as `ranks`, and the traffic (rays, spill, textures) merged over them. Rank 0's own
// peak of rays in RAM stays its own.
void addRanksToStats(const std::vector<std::string>& all, RenderStats& stats) {
    nlohmann::json perRank = nlohmann::json::array();
    RenderStats total;
    for (size_t r = 0; r < all.size(); ++r) {
        const nlohmann::json j = nlohmann::json::parse(all[r]);
        RenderStats counters;
        counters.readCounters(j);
        total.mergeCounters(counters);
        nlohmann::json entry = {{"rank", r},
                                {"host", j.value("host", "")},
                                {"threads", j["threads"]},
                                {"wall_seconds", j["wall_seconds"]},
                                {"render_seconds", j["render_seconds"]},
                                {"reduce_seconds", j["stage_seconds"].value("reduce", 0.0)},
                                {"agree_seconds", j["stage_seconds"].value("agree", 0.0)}};
        entry.update(counters.countersJson());
        perRank.push_back(entry);
    }
    stats.cameraRays = total.cameraRays.load();
    stats.bounceRays = total.bounceRays.load();
    stats.shadowRays = total.shadowRays.load();
    if (total.spill) {
        total.spill->peakRayBytesInRam = stats.spill ? stats.spill->peakRayBytesInRam : 0;
        stats.spill = total.spill;
    }
    stats.textures = total.textures;
    stats.extra["ranks"] = perRank;
}

} // namespace

void RankSync::agreeIdentity(const std::function<RenderIdentity()>& identity) {
    const RenderIdentity fields = identity();
    std::vector<std::uint64_t> digests;
    for (const auto& field : fields)
        digests.push_back(field.second);
    // A rank that failed before the render (its scene, its options) says so in an agreement:
    // meet it there first, so that the exchange below only runs where every rank reached it.
    ranks_.agree(false, false, false);
    const std::vector<int> differs = ranks_.firstDifferences(digests);
    for (size_t r = 0; r < differs.size(); ++r)
        if (differs[r] >= 0) {
            ranks_.finish(); // every rank leaves here, together: no collective follows
            throw RenderRefused("rank " + std::to_string(r) + " would render another " +
                                fields[size_t(differs[r])].first + " than rank 0 (every rank " +
                                "must load the same scene and files with the same options)");
        }
}

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
    // First which fine-level tiles any rank reached (Film::levelTilesReached), then the sums.
    std::vector<std::int64_t> tiles = film.levelTilesReached();
    ranks_.sum(tiles);
    std::vector<std::int64_t> sums = film.iterationAccumulators(tiles);
    ranks_.sum(sums);
    film.setIterationAccumulators(sums, tiles);
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
