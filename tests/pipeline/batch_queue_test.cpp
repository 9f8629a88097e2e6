// The batch queue on its own: batches come back byte for byte and in order whether they stayed
// in RAM or went through the spill file; the budget decides which; the counters say what moved;
// buffers handed back are handed out again rather than freed; the spill file reuses its space.
#include "host/pipeline/batch_queue.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace spw {
namespace {

RayBatch patternBatch(size_t bytes, std::uint8_t seed) {
    RayBatch b;
    b.count = bytes / rayRecordBytes(RayFormat::Compact);
    b.bin = seed % 6;
    b.bytes.resize(bytes);
    for (size_t i = 0; i < bytes; ++i)
        b.bytes[i] = std::uint8_t(seed * 31 + i * 7 + (i >> 9));
    return b;
}

TEST(BatchQueue, BatchesComeBackIntactAndInOrderFromRamAndDisk) {
    const char* tmp = std::getenv("TMPDIR");
    // A budget of two batches: the first two stay in RAM, the other four spill.
    const size_t size = 100 * 1024;
    BatchQueue queue(2 * size, tmp ? tmp : "");
    for (std::uint8_t k = 0; k < 6; ++k)
        queue.push(patternBatch(size, k));
    QueueCounters c = queue.counters();
    EXPECT_EQ(c.batchesQueued, 6u);
    EXPECT_EQ(c.batchesSpilled, 4u);
    EXPECT_EQ(c.bytesWritten, 4 * size);
    StageTimes times;
    for (std::uint8_t k = 0; k < 6; ++k) {
        std::optional<RayBatch> b = queue.pop(times);
        ASSERT_TRUE(b) << "batch " << int(k);
        const RayBatch want = patternBatch(size, k);
        EXPECT_EQ(b->bin, want.bin);
        EXPECT_EQ(b->count, want.count);
        EXPECT_TRUE(b->bytes == want.bytes) << "batch " << int(k) << " changed on its way";
        queue.recycle(std::move(b->bytes));
    }
    EXPECT_FALSE(queue.pop(times));
    EXPECT_TRUE(queue.empty());
    c = queue.counters();
    EXPECT_EQ(c.bytesRead, 4 * size);
    EXPECT_EQ(c.peakRamBytes, 2 * size);
}

// Many spilled batches through the reader thread and the consumer's own reads, the queue
// never more than three deep (as the renderer keeps it): every batch back intact, in order,
// the file's ranges reused, and a clear() with a read in flight leaving the queue usable.
TEST(BatchQueue, SpilledBatchesSurviveReadAheadAndTakeOver) {
    const char* tmp = std::getenv("TMPDIR");
    BatchQueue queue(0, tmp ? tmp : "");
    StageTimes times;
    const size_t size = 64 * 1024;
    std::uint8_t next = 0, expected = 0;
    for (int round = 0; round < 200; ++round) {
        while (next - expected < 3)
            queue.push(patternBatch(size, next++));
        std::optional<RayBatch> b = queue.pop(times);
        ASSERT_TRUE(b);
        ASSERT_TRUE(b->bytes == patternBatch(size, expected).bytes) << "batch " << round;
        ++expected;
        queue.recycle(std::move(b->bytes));
    }
    queue.clear();
    EXPECT_TRUE(queue.empty());
    queue.push(patternBatch(size, 7));
    std::optional<RayBatch> b = queue.pop(times);
    ASSERT_TRUE(b);
    EXPECT_TRUE(b->bytes == patternBatch(size, 7).bytes);
    const QueueCounters c = queue.counters();
    EXPECT_EQ(c.batchesSpilled, 203u);  // 3 + 199 in the loop, then one more
    EXPECT_EQ(c.bytesRead, 201 * size); // the two cleared batches were never read
}

// The spill file hands out the ranges of batches read back before growing, first fit, with
// freed neighbours merged so that a full batch fits where two smaller ones were.
TEST(SpillFile, ReadBackRangesAreReusedAndNeighboursMerged) {
    const char* tmp = std::getenv("TMPDIR");
    SpillFile file(tmp && *tmp ? tmp : "/tmp");
    EXPECT_EQ(file.reserve(100), 0u);
    EXPECT_EQ(file.reserve(100), 100u);
    EXPECT_EQ(file.reserve(50), 200u);
    file.release(100, 100);
    file.release(0, 100); // merged with [100, 200)
    EXPECT_EQ(file.reserve(150), 0u);
    EXPECT_EQ(file.reserve(60), 250u); // [150, 200) is too small: the end
    EXPECT_EQ(file.reserve(50), 150u); // but fits this one exactly
    // Bytes written to a reused range read back as written.
    file.release(0, 150);
    std::vector<std::uint8_t> out(150), in(150);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = std::uint8_t(i * 13 + 5);
    const std::uint64_t at = file.reserve(150);
    EXPECT_EQ(at, 0u);
    file.write(at, out);
    file.read(at, in);
    EXPECT_TRUE(in == out);
}

TEST(BatchQueue, RecycledBuffersAreHandedOutAgainEmptyWithTheirCapacity) {
    BatchQueue queue(0, "");
    EXPECT_EQ(queue.spareBuffer().capacity(), 0u); // nothing recycled yet: a new, empty one
    std::vector<std::uint8_t> used(4096, 7);
    const std::uint8_t* storage = used.data();
    queue.recycle(std::move(used));
    std::vector<std::uint8_t> again = queue.spareBuffer();
    EXPECT_EQ(again.data(), storage); // the same allocation, not a copy
    EXPECT_TRUE(again.empty());
    EXPECT_GE(again.capacity(), 4096u);
    EXPECT_EQ(queue.spareBuffer().capacity(), 0u); // it was handed out once
    // The pool is bounded: what is recycled beyond it is freed.
    for (int i = 0; i < 100; ++i)
        queue.recycle(std::vector<std::uint8_t>(64));
    int spares = 0;
    while (queue.spareBuffer().capacity() > 0)
        ++spares;
    EXPECT_GT(spares, 0);
    EXPECT_LE(spares, 8);
}

} // namespace
} // namespace spw
