#include "host/pipeline/directional_bins.h"

#include "host/simd/lanes.h"

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

// Room for a record at the end of bin b's bytes: the vector only grows (zero-filled once, by
// doubling); `used` says how much holds rays.
std::uint8_t* RayBuffer::reserve(uint b, size_t bytes) {
    std::vector<std::uint8_t>& dst = perBin[b];
    if (dst.size() < used[b] + bytes) dst.resize(std::max(dst.size() * 2, 256 * kFullRayBytes));
    std::uint8_t* at = dst.data() + used[b];
    used[b] += bytes;
    ++count;
    return at;
}

void RayBuffer::push(vec3 origin, vec3 dir, const PathState& path, RayFormat format,
                     uvec4 rounding) {
    encodeRay(origin, dir, path, format, rounding,
              reserve(cardinalBin(dir), rayRecordBytes(format)));
}

void RayBuffer::pushContinuations(const RenderParams& rp, RayFormat format, const ShadeResult* res,
                                  size_t n) {
    if (format == RayFormat::Full) { // every bit kept: nothing to round, nothing SIMD-wide
        for (size_t i = 0; i < n; ++i)
            if (res[i].flags & kShadeContinue)
                push(res[i].nextOrigin, res[i].nextDir, res[i].next, format, uvec4(0u));
        return;
    }
    const ShadeResult* block[simd::kBlock];
    std::uint8_t records[simd::kBlock * kCompactRayBytes], bins[simd::kBlock];
    size_t count = 0;
    auto flush = [&] {
        encodeCompactBlock(rp, block, count, records, bins);
        for (size_t k = 0; k < count; ++k)
            std::memcpy(reserve(bins[k], kCompactRayBytes), records + k * kCompactRayBytes,
                        kCompactRayBytes);
        count = 0;
    };
    for (size_t i = 0; i < n; ++i) {
        if (!(res[i].flags & kShadeContinue)) continue;
        block[count++] = &res[i];
        if (count == simd::kBlock) flush();
    }
    if (count > 0) flush();
}

} // namespace spw
