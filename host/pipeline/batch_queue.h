// Ray batches and where they wait: six directional bins, then a FIFO queue of batches that
// holds at most `memory budget` bytes in RAM and spills the rest to disk.
//
// Spilling: all spilled batches share one file in the spill folder, opened with O_TMPFILE (or
// created and unlinked at once where the file system lacks it), so it has no name from the
// start: whatever way the process ends, normal exit, exception, SIGINT, SIGTERM or SIGKILL, the
// kernel frees it and no file is left behind. Each batch is one large pwrite and one pread back.
// The range of a batch read back is free for the next one (first fit, neighbours merged), so
// the file stays at the most bytes ever queued on disk at once, and a write lands in pages the
// kernel already holds for the file rather than new ones it must allocate, account and later
// drop by punching a hole: pwrite 103 -> 40 us for a 1.1 MB batch, and no fallocate (29 us).
// The write happens outside the queue's lock (its range is reserved under it), so one worker's
// write holds up neither the others' pushes nor the consumer's pop.
//
// Batch buffers are recycled: a batch's bytes, once decoded or written to disk, go back to the
// queue, which hands them to the bins and to its reads. A batch of 2^15 rays is about 1 MB, above
// glibc's mmap threshold, so without recycling every batch would map fresh pages and fault each
// one in.
#pragma once

#include "host/backend/stats.h"
#include "host/pipeline/ray_record.h"

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

class SpillFile {
  public:
    // Throws std::runtime_error naming `dir` when no file can be made there.
    explicit SpillFile(const std::string& dir);
    ~SpillFile();
    SpillFile(const SpillFile&) = delete;
    SpillFile& operator=(const SpillFile&) = delete;
    // The offset of `size` bytes for write(): free space a read-back batch left, else the
    // file's end. Thread-safe.
    std::uint64_t reserve(std::uint64_t size);
    // Throws naming the folder on any write error (a full disk). Thread-safe.
    void write(std::uint64_t offset, const std::vector<std::uint8_t>& bytes);
    void read(std::uint64_t offset, std::vector<std::uint8_t>& bytes);
    // The range is free for reserve(). Thread-safe.
    void release(std::uint64_t offset, std::uint64_t size);
    const std::string& dir() const { return dir_; }

  private:
    std::string dir_;
    int fd_ = -1;
    std::mutex mutex_;
    std::uint64_t end_ = 0;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> free_; // (offset, size), by offset
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

// A thread-local buffer of encoded rays, already split by cardinal bin.
struct RayBuffer {
    std::vector<std::uint8_t> perBin[6]; // bytes [0, used[b]) of bin b hold encoded rays
    size_t used[6] = {};
    size_t count = 0;
    void push(vec3 origin, vec3 dir, const PathState& path, RayFormat format, uvec4 rounding);
};

// Six cardinal-direction bins. Rays arrive in thread-local buffers; a bin holding 2^e rays
// becomes a batch of exactly 2^e rays in the queue (a buffer larger than a batch simply makes
// several). When the queue runs dry, the part-full bins are flushed, the fullest first, into one
// batch of up to 2^e rays.
class DirectionalBins {
  public:
    DirectionalBins(RayFormat format, uint binExponent, BatchQueue& queue);
    // Thread-safe. Takes the buffer's rays (leaving it empty, capacity kept).
    void add(RayBuffer& buffer);
    // Moves the rays of part-full bins into the queue as one batch of up to 2^e rays, the
    // fullest bins first: the end of an iteration, where bins fill slowly, makes a few mixed
    // batches rather than many small ones. False when every bin is empty.
    bool flush();
    size_t raysWaiting();
    // Drops every waiting ray (a stopped render).
    void clear();

  private:
    struct Bin {
        std::mutex mutex;
        std::vector<std::uint8_t> bytes;
    };
    RayFormat format_;
    size_t recordBytes_;
    size_t batchRays_;
    BatchQueue& queue_;
    Bin bins_[6];
};

} // namespace spw
