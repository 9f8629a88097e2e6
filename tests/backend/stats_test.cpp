// --stats' typed counters (host/backend/stats.h): what toJson writes, readCounters reads back
// whole, and mergeCounters adds them up as a distributed render's totals need (sums, the texture
// cache's peak as a maximum, each rank's peak of rays in RAM its own).
#include "host/backend/stats.h"

#include <gtest/gtest.h>

namespace spw {
namespace {

void fill(RenderStats& s, std::uint64_t base) {
    s.cameraRays = base + 1;
    s.bounceRays = base + 2;
    s.shadowRays = base + 3;
    s.spill = SpillCounters{base + 4, base + 5, base + 6, base + 7, base + 8, base + 9};
    s.textures = TextureCounters{base + 10, base + 11, base + 12, base + 13,
                                 base + 14, base + 15, base + 16};
}

TEST(Stats, CountersRoundTripThroughTheirJson) {
    RenderStats written;
    fill(written, 100);
    RenderStats read;
    read.readCounters(written.toJson());
    EXPECT_EQ(read.cameraRays.load(), 101u);
    EXPECT_EQ(read.bounceRays.load(), 102u);
    EXPECT_EQ(read.shadowRays.load(), 103u);
    ASSERT_TRUE(read.spill && read.textures);
    EXPECT_TRUE(*read.spill == *written.spill);
    EXPECT_TRUE(*read.textures == *written.textures);
    EXPECT_EQ(read.countersJson(), written.countersJson());

    RenderStats none;
    none.readCounters(RenderStats{}.toJson()); // the reference backend: no spill, no textures
    EXPECT_FALSE(none.spill || none.textures);
}

TEST(Stats, MergeSumsTrafficAndKeepsTheLargestCachePeak) {
    RenderStats a, b;
    fill(a, 100);
    fill(b, 1000);
    b.textures->peakCacheBytes = 5; // below a's
    a.mergeCounters(b);
    EXPECT_EQ(a.cameraRays.load(), 101u + 1001u);
    EXPECT_EQ(a.shadowRays.load(), 103u + 1003u);
    EXPECT_EQ(a.spill->batchesProcessed, 104u + 1004u);
    EXPECT_EQ(a.spill->bytesRead, 108u + 1008u);
    EXPECT_EQ(a.spill->peakRayBytesInRam, 109u) << "each process's own";
    EXPECT_EQ(a.textures->lookups, 110u + 1010u);
    EXPECT_EQ(a.textures->cacheMisses, 115u + 1015u);
    EXPECT_EQ(a.textures->peakCacheBytes, 116u);
    // Per ray: the merged lookups over the merged rays.
    const nlohmann::json j = a.toJson();
    EXPECT_DOUBLE_EQ(j["textures"]["per_ray"]["lookups"].get<double>(),
                     double(110 + 1010) / double(101 + 102 + 103 + 1001 + 1002 + 1003));
}

} // namespace
} // namespace spw
