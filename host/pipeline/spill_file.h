// The spill file: where ray batches beyond the memory budget wait (batch_queue.h).
//
// All spilled batches share one file in the spill folder, opened with O_TMPFILE (or
// created and unlinked at once where the file system lacks it), so it has no name from the
// start: whatever way the process ends, normal exit, exception, SIGINT, SIGTERM or SIGKILL, the
// kernel frees it and no file is left behind. Each batch is one large pwrite and one pread back.
// The range of a batch read back is free for the next one (first fit, neighbours merged), so
// the file stays at the most bytes ever queued on disk at once, and a write lands in pages the
// kernel already holds for the file rather than new ones it must allocate, account and later
// drop by punching a hole: pwrite 103 -> 40 us for a 1.1 MB batch, and no fallocate (29 us).
// The write happens outside the queue's lock (its range is reserved under it), so one worker's
// write holds up neither the others' pushes nor the consumer's pop.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace spw {

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

} // namespace spw
