// Ray batches and the FIFO queue where they wait once the directional bins (directional_bins.h)
// made them: it holds at most `memory budget` bytes in RAM and spills the rest to disk.
//
// Spilling goes to one nameless file (spill_file.h).
//
// Batch buffers are recycled: a batch's bytes, once decoded or written to disk, go back to the
// queue, which hands them to the bins and to its reads. A batch of 2^15 rays is about 1 MB, above
// glibc's mmap threshold, so without recycling every batch would map fresh pages and fault each
// one in.
#pragma once

#include "host/backend/stats.h"
#include "host/pipeline/ray_record.h"
#include "host/pipeline/spill_file.h"

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace spw {

struct RayBatch {
    RayFormat format = RayFormat::Compact;
    size_t count = 0;
    std::vector<std::uint8_t> bytes; // count * record size
    uint bin = 0; // cardinal bin the rays came from (a flushed batch: its fullest bin)
};

// Traffic counters for --stats.
struct QueueCounters {
    std::uint64_t batchesQueued = 0, batchesSpilled = 0, bytesWritten = 0, bytesRead = 0;
    std::uint64_t peakRamBytes = 0; // queued batches in RAM + rays waiting in bins
};

class BatchQueue {
  public:
    // `budgetBytes`: queued batches held in RAM. `spillDir`: empty for the system temp folder.
    BatchQueue(std::uint64_t budgetBytes, std::string spillDir);
    ~BatchQueue();

    // Thread-safe. Keeps the batch in RAM if it fits the budget, else spills it.
    void push(RayBatch&& batch);
    // Not thread-safe with itself (one consumer). The next batch, loaded. A spilled batch at
    // the front is read ahead by the queue's reader thread; if that thread has not started on
    // it when it is wanted (two busy cores), the consumer reads it itself rather than wait.
    std::optional<RayBatch> pop(StageTimes& times);
    bool empty() const;
    // Drops every queued batch (a stopped render): waits for a read in flight, frees the spill
    // file's space. Not thread-safe with pop().
    void clear();
    // Bytes of rays waiting outside the queue (bins), for the peak-RAM statistic.
    void noteOutsideBytes(std::int64_t delta);
    // Thread-safe. A batch buffer to fill (empty, its capacity kept from an earlier batch when
    // one was recycled), and the way back for one that is done with.
    std::vector<std::uint8_t> spareBuffer();
    void recycle(std::vector<std::uint8_t>&& bytes);
    QueueCounters counters() const;

  private:
    struct Entry {
        RayBatch batch; // bytes empty when spilled
        bool spilled = false;
        std::uint64_t offset = 0, size = 0;
    };
    // The read-ahead of entries_.front() when it is spilled (all under the mutex).
    struct ReadAhead {
        enum State { kIdle, kQueued, kReading, kDone } state = kIdle;
        SpillFile* file = nullptr;
        std::uint64_t offset = 0, size = 0;
        std::vector<std::uint8_t> bytes;
        std::exception_ptr error;
    };
    void append(Entry&& e); // with the mutex held
    void startPrefetch();   // with the mutex held
    void readerLoop();
    // Reads [offset, offset + size) into a spare buffer and frees the range in the file.
    std::vector<std::uint8_t> readBack(SpillFile& file, std::uint64_t offset, std::uint64_t size);
    SpillFile& spill();

    mutable std::mutex mutex_;
    std::deque<Entry> entries_;
    std::uint64_t budget_, ramBytes_ = 0;
    std::int64_t outsideBytes_ = 0;
    std::string spillDir_;
    std::unique_ptr<SpillFile> spill_;
    ReadAhead ahead_;
    std::condition_variable wake_, done_; // the reader's work, and its result
    bool stop_ = false;
    std::thread reader_; // started with the first spill
    QueueCounters counters_;
    std::mutex spareMutex_;
    std::vector<std::vector<std::uint8_t>> spare_; // at most kSpareBuffers
};

} // namespace spw
