// Six cardinal-direction bins, where the rays a stage makes wait until a bin holds a batch, and
// the thread-local buffers that fill them.
#pragma once

#include "host/pipeline/batch_queue.h"
#include "host/pipeline/ray_record.h"

#include <cstdint>
#include <mutex>
#include <vector>

namespace spw {

// A thread-local buffer of encoded rays, already split by cardinal bin.
struct RayBuffer {
    std::vector<std::uint8_t> perBin[6]; // bytes [0, used[b]) of bin b hold encoded rays
    size_t used[6] = {};
    size_t count = 0;
    void push(vec3 origin, vec3 dir, const PathState& path, RayFormat format, uvec4 rounding);
    // The continuation rays of n shading results (those with kShadeContinue), each rounded with
    // its path's compactRounding; compact records are made a block at a time, SIMD-wide
    // (encodeCompactBlock).
    void pushContinuations(const RenderParams& rp, RayFormat format, const ShadeResult* res,
                           size_t n);

  private:
    std::uint8_t* reserve(uint bin, size_t bytes);
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
