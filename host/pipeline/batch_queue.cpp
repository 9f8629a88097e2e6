#include "host/pipeline/batch_queue.h"

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

// ---------------------------------------------------------------------------- SpillFile

SpillFile::SpillFile(const std::string& dir) : dir_(dir) {
#ifdef O_TMPFILE
    fd_ = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
    if (fd_ < 0) {
        // No O_TMPFILE here: make a named file and unlink it before anything else happens.
        std::string templ = dir + "/spillway-spill-XXXXXX";
        std::vector<char> name(templ.begin(), templ.end());
        name.push_back('\0');
        fd_ = ::mkostemp(name.data(), O_CLOEXEC);
        if (fd_ >= 0) ::unlink(name.data());
    }
    if (fd_ < 0)
        throw std::runtime_error("cannot create a spill file in '" + dir +
                                 "': " + std::strerror(errno));
}

SpillFile::~SpillFile() {
    if (fd_ >= 0) ::close(fd_);
}

void SpillFile::write(std::uint64_t offset, const std::vector<std::uint8_t>& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
            throw std::runtime_error("cannot write ray batch to the spill file in '" + dir_ +
                                     "': " + (n < 0 ? std::strerror(errno) : "no space left"));
        done += size_t(n);
    }
}

void SpillFile::read(std::uint64_t offset, std::vector<std::uint8_t>& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::pread(fd_, bytes.data() + done, bytes.size() - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
            throw std::runtime_error("cannot read ray batch back from the spill file in '" + dir_ +
                                     "': " + (n < 0 ? std::strerror(errno) : "file ended early"));
        done += size_t(n);
    }
}

std::uint64_t SpillFile::reserve(std::uint64_t size) {
    std::lock_guard<std::mutex> lock(mutex_);
    // First fit: batches are mostly of one size (2^e rays), so the first free range fits.
    for (auto it = free_.begin(); it != free_.end(); ++it)
        if (it->second >= size) {
            const std::uint64_t offset = it->first;
            it->first += size;
            it->second -= size;
            if (it->second == 0) free_.erase(it);
            return offset;
        }
    const std::uint64_t offset = end_;
    end_ += size;
    return offset;
}

void SpillFile::release(std::uint64_t offset, std::uint64_t size) {
    if (size == 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    // Kept sorted by offset, neighbours merged, so that freed batches make room for full ones.
    auto it =
        std::lower_bound(free_.begin(), free_.end(), std::make_pair(offset, std::uint64_t(0)));
    it = free_.insert(it, {offset, size});
    if (std::next(it) != free_.end() && it->first + it->second == std::next(it)->first) {
        it->second += std::next(it)->second;
        free_.erase(std::next(it));
    }
    if (it != free_.begin() && std::prev(it)->first + std::prev(it)->second == it->first) {
        std::prev(it)->second += it->second;
        free_.erase(it);
    }
}

// ---------------------------------------------------------------------------- BatchQueue

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
        // The system temp folder as std::filesystem::temp_directory_path() finds it, but without
        // its check that the folder exists: that is the spill file's to report, if it is needed.
        std::string dir = spillDir_;
        for (const char* var : {"TMPDIR", "TMP", "TEMP", "TEMPDIR"})
            if (dir.empty() && std::getenv(var) && *std::getenv(var)) dir = std::getenv(var);
        spill_ = std::make_unique<SpillFile>(dir.empty() ? "/tmp" : dir);
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

// ---------------------------------------------------------------------------- DirectionalBins

DirectionalBins::DirectionalBins(RayFormat format, uint binExponent, BatchQueue& queue)
    : format_(format), recordBytes_(rayRecordBytes(format)), batchRays_(size_t(1) << binExponent),
      queue_(queue) {}

void DirectionalBins::add(RayBuffer& buffer) {
    const size_t batchBytes = batchRays_ * recordBytes_;
    for (uint b = 0; b < 6; ++b) {
        const std::vector<std::uint8_t>& src = buffer.perBin[b];
        const size_t srcBytes = buffer.used[b];
        if (srcBytes == 0) continue;
        // Each bin fills its batch in place; a full batch leaves for the queue (outside the
        // lock) and the next one starts. A buffer of any size simply makes several batches.
        std::vector<RayBatch> full;
        size_t at = 0;
        {
            std::lock_guard<std::mutex> lock(bins_[b].mutex);
            std::vector<std::uint8_t>& bin = bins_[b].bytes;
            while (at < srcBytes) {
                if (bin.capacity() < batchBytes) bin.reserve(batchBytes);
                const size_t take = std::min(srcBytes - at, batchBytes - bin.size());
                bin.insert(bin.end(), src.begin() + std::ptrdiff_t(at),
                           src.begin() + std::ptrdiff_t(at + take));
                at += take;
                if (bin.size() == batchBytes) {
                    RayBatch batch;
                    batch.format = format_;
                    batch.count = batchRays_;
                    batch.bin = b;
                    batch.bytes.swap(bin);
                    bin = queue_.spareBuffer();
                    full.push_back(std::move(batch));
                }
            }
        }
        queue_.noteOutsideBytes(std::int64_t(srcBytes) - std::int64_t(full.size() * batchBytes));
        buffer.used[b] = 0;
        for (RayBatch& batch : full)
            queue_.push(std::move(batch));
    }
    buffer.count = 0;
}

bool DirectionalBins::flush() {
    // Every bin holds less than a batch (a full one has left already). Lock them all, in order.
    std::unique_lock<std::mutex> locks[6];
    int order[6];
    for (int b = 0; b < 6; ++b) {
        locks[b] = std::unique_lock<std::mutex>(bins_[b].mutex);
        order[b] = b;
    }
    std::stable_sort(order, order + 6,
                     [&](int a, int b) { return bins_[a].bytes.size() > bins_[b].bytes.size(); });
    if (bins_[order[0]].bytes.empty()) return false;
    // The fullest bin, then the next fullest, until the batch is full: the last one taken may
    // give only the end of its rays.
    const size_t batchBytes = batchRays_ * recordBytes_;
    RayBatch batch;
    batch.bytes.swap(bins_[order[0]].bytes);
    batch.bin = uint(order[0]);
    for (int k = 1; k < 6 && batch.bytes.size() < batchBytes; ++k) {
        std::vector<std::uint8_t>& bin = bins_[order[k]].bytes;
        const size_t take = std::min(bin.size(), batchBytes - batch.bytes.size());
        batch.bytes.insert(batch.bytes.end(), bin.end() - std::ptrdiff_t(take), bin.end());
        bin.resize(bin.size() - take);
    }
    for (auto& lock : locks)
        lock.unlock();
    batch.format = format_;
    batch.count = batch.bytes.size() / recordBytes_;
    queue_.noteOutsideBytes(-std::int64_t(batch.bytes.size()));
    queue_.push(std::move(batch));
    return true;
}

void DirectionalBins::clear() {
    for (Bin& b : bins_) {
        std::lock_guard<std::mutex> lock(b.mutex);
        queue_.noteOutsideBytes(-std::int64_t(b.bytes.size()));
        b.bytes.clear();
    }
}

size_t DirectionalBins::raysWaiting() {
    size_t n = 0;
    for (Bin& b : bins_) {
        std::lock_guard<std::mutex> lock(b.mutex);
        n += b.bytes.size();
    }
    return n / recordBytes_;
}

void RayBuffer::push(vec3 origin, vec3 dir, const PathState& path, RayFormat format,
                     uvec4 rounding) {
    const uint b = cardinalBin(dir);
    const size_t bytes = rayRecordBytes(format);
    std::vector<std::uint8_t>& dst = perBin[b];
    // The vector only grows (zero-filled once, by doubling); `used` says how much holds rays.
    if (dst.size() < used[b] + bytes) dst.resize(std::max(dst.size() * 2, 256 * kFullRayBytes));
    encodeRay(origin, dir, path, format, rounding, dst.data() + used[b]);
    used[b] += bytes;
    ++count;
}

} // namespace spw
