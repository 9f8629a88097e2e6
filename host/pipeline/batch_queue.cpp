#include "host/pipeline/batch_queue.h"

#include "host/image/scratch_file.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <iterator>
#include <stdexcept>
#include <unistd.h>
#include <utility>

namespace spw {

BatchQueue::BatchQueue(std::uint64_t budgetBytes, std::string spillDir)
    : budget_(budgetBytes), spillDir_(std::move(spillDir)) {}

BatchQueue::~BatchQueue() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (reader_.joinable()) reader_.join();
}

SpillFile& BatchQueue::spill() {
    if (!spill_) {
        spill_ = std::make_unique<SpillFile>(scratchFolder(spillDir_));
    }
    return *spill_;
}

void BatchQueue::push(RayBatch&& batch) {
    Entry e;
    e.size = batch.bytes.size();
    SpillFile* file = nullptr;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        ++counters_.batchesQueued;
        if (ramBytes_ + e.size <= budget_) {
            ramBytes_ += e.size;
            e.batch = std::move(batch);
            append(std::move(e));
            return;
        }
        file = &spill();
        e.offset = file->reserve(e.size);
    }
    // The write, outside the lock; the entry is queued once its bytes are on disk.
    file->write(e.offset, batch.bytes);
    recycle(std::move(batch.bytes));
    batch.bytes = {};
    e.spilled = true;
    e.batch = std::move(batch);
    std::lock_guard<std::mutex> lock(mutex_);
    counters_.bytesWritten += e.size;
    ++counters_.batchesSpilled;
    append(std::move(e));
}

void BatchQueue::append(Entry&& e) {
    // Called with the mutex held.
    counters_.peakRamBytes = std::max<std::uint64_t>(
        counters_.peakRamBytes,
        ramBytes_ + std::uint64_t(std::max<std::int64_t>(0, outsideBytes_)));
    entries_.push_back(std::move(e));
    if (entries_.size() == 1) startPrefetch();
}

std::vector<std::uint8_t> BatchQueue::spareBuffer() {
    std::vector<std::uint8_t> bytes;
    std::lock_guard<std::mutex> lock(spareMutex_);
    if (!spare_.empty()) {
        bytes.swap(spare_.back());
        spare_.pop_back();
    }
    return bytes;
}

void BatchQueue::recycle(std::vector<std::uint8_t>&& bytes) {
    // A few buffers cover the batches in motion at once (one per worker filling a bin, one being
    // read back, one being decoded); the rest are freed.
    constexpr size_t kSpareBuffers = 4;
    bytes.clear();
    std::lock_guard<std::mutex> lock(spareMutex_);
    if (spare_.size() < kSpareBuffers && bytes.capacity() > 0) spare_.push_back(std::move(bytes));
}

void BatchQueue::startPrefetch() {
    if (entries_.empty() || !entries_.front().spilled || ahead_.state != ReadAhead::kIdle) return;
    const Entry& e = entries_.front();
    ahead_.state = ReadAhead::kQueued;
    ahead_.file = &spill();
    ahead_.offset = e.offset;
    ahead_.size = e.size;
    if (!reader_.joinable()) reader_ = std::thread([this] { readerLoop(); });
    wake_.notify_one();
}

void BatchQueue::readerLoop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        wake_.wait(lock, [&] { return stop_ || ahead_.state == ReadAhead::kQueued; });
        if (stop_) return;
        ahead_.state = ReadAhead::kReading;
        SpillFile& file = *ahead_.file;
        const std::uint64_t offset = ahead_.offset, size = ahead_.size;
        lock.unlock();
        std::vector<std::uint8_t> bytes;
        std::exception_ptr error;
        try {
            bytes = readBack(file, offset, size);
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        ahead_.bytes = std::move(bytes);
        ahead_.error = error;
        ahead_.state = ReadAhead::kDone;
        done_.notify_all();
    }
}

std::vector<std::uint8_t> BatchQueue::readBack(SpillFile& file, std::uint64_t offset,
                                               std::uint64_t size) {
    std::vector<std::uint8_t> bytes = spareBuffer();
    bytes.resize(size);
    file.read(offset, bytes);
    file.release(offset, size);
    return bytes;
}

std::optional<RayBatch> BatchQueue::pop(StageTimes& times) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (entries_.empty()) return std::nullopt;
    Entry e = std::move(entries_.front());
    entries_.pop_front();
    if (e.spilled) {
        StageTimer t(times, "load");
        if (ahead_.state == ReadAhead::kQueued) {
            // The reader has not got to it: read it here rather than wait for the reader to be
            // scheduled (it finds nothing to do).
            ahead_.state = ReadAhead::kIdle;
            SpillFile& file = *ahead_.file;
            lock.unlock();
            e.batch.bytes = readBack(file, e.offset, e.size);
            lock.lock();
        } else {
            done_.wait(lock, [&] { return ahead_.state == ReadAhead::kDone; });
            ahead_.state = ReadAhead::kIdle;
            if (ahead_.error) std::rethrow_exception(std::exchange(ahead_.error, nullptr));
            e.batch.bytes = std::move(ahead_.bytes);
        }
        counters_.bytesRead += e.size;
    } else {
        ramBytes_ -= e.size;
    }
    startPrefetch();
    return std::move(e.batch);
}

void BatchQueue::clear() {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return ahead_.state != ReadAhead::kReading; });
    // A finished read-back released the front entry's range itself; its bytes are dropped, and
    // so is a read error on rays that are being dropped anyway.
    const bool frontReleased = ahead_.state == ReadAhead::kDone && !ahead_.error;
    ahead_.state = ReadAhead::kIdle;
    ahead_.error = nullptr;
    recycle(std::move(ahead_.bytes));
    ahead_.bytes = {};
    for (size_t i = 0; i < entries_.size(); ++i) {
        const Entry& e = entries_[i];
        if (!e.spilled)
            ramBytes_ -= e.size;
        else if (i > 0 || !frontReleased)
            spill_->release(e.offset, e.size);
    }
    entries_.clear();
}

bool BatchQueue::empty() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return entries_.empty();
}

void BatchQueue::noteOutsideBytes(std::int64_t delta) {
    std::lock_guard<std::mutex> lock(mutex_);
    outsideBytes_ += delta;
    counters_.peakRamBytes = std::max<std::uint64_t>(
        counters_.peakRamBytes,
        ramBytes_ + std::uint64_t(std::max<std::int64_t>(0, outsideBytes_)));
}

QueueCounters BatchQueue::counters() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return counters_;
}

} // namespace spw
