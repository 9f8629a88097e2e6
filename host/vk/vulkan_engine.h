// The Vulkan shading engine's class, shared by its two sources: vulkan_setup.cpp (what the
// constructor builds: kernels, binding windows, command objects, the scene's tables, pipelines)
// and vulkan_shading.cpp (each batch: reserve, record, submit, finish, and the stats). Private to
// host/vk: the rest of the renderer sees makeVulkanShading() (vulkan_shading.h) alone.
#pragma once

#include "host/pipeline/slotted_engine.h"
#include "host/vk/vulkan_shading.h"

#include "host/scene/surface_models.h"
#include "host/vk/buffer.h"
#include "host/vk/check.h"
#include "host/vk/context.h"
#include "host/vk/pipelines.h"
#include "shared/shade_io.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <numeric>
#include <stdexcept>

#include <memory>
#include <string>
#include <vector>

namespace spw::vk_engine {

using vk::HostArray;
using vk::zeroed;

constexpr size_t kSlots = 2;
constexpr size_t kMinCapacity = 1024; // records: the smallest buffers a slot allocates

// Timestamps written per submit: before the upload, after it, after the dispatches, after the
// download. They go to one pool shared by the slots and are read only when no batch is in
// flight (end of iteration, or the pool full): reading sooner stalls lavapipe, whose query
// read waits for everything queued, here the other slot's batch.
constexpr uint32_t kTimestamps = 4;
constexpr uint32_t kQueryCapacity = kTimestamps * 512;

inline double seconds(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

inline void barrier(VkCommandBuffer cmd, VkPipelineStageFlags src, VkAccessFlags srcAccess,
                    VkPipelineStageFlags dst, VkAccessFlags dstAccess) {
    auto b = zeroed<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cmd, src, dst, 0, 1, &b, 0, nullptr, 0, nullptr);
}

// A view of `range` bytes of `buffer` from `offset` as texels of `format`, for a uniform texel
// buffer binding.
inline VkBufferView makeTexelView(VkDevice device, VkBuffer buffer, VkFormat format,
                                  VkDeviceSize offset, VkDeviceSize range) {
    auto info = zeroed<VkBufferViewCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO);
    info.buffer = buffer;
    info.format = format;
    info.offset = offset;
    info.range = range;
    VkBufferView view = VK_NULL_HANDLE;
    SPW_VK_CHECK(vkCreateBufferView(device, &info, nullptr, &view));
    return view;
}

// The words of a record as texels: R32G32B32A32_UINT, 16 bytes each.
constexpr VkDeviceSize kTexelBytes = 16;

// Hits are always sorted for Vulkan (one homogeneous dispatch per shader range is the engine's
// point), unless --hit-sort off or --shading megakernel asks otherwise.
class VulkanShading : public SlottedEngine {
  public:
    VulkanShading(const RenderContext& ctx, const PipelineConfig& pipeline, vk::Context& context);
    ~VulkanShading() override;

    void beginIteration(uint iteration) override {
        SlottedEngine::beginIteration(iteration);
        params_.iteration = iteration;
    }
    void publishStats(RenderStats& stats) override;

    int slots() const override { return int(kSlots); }
    ShadeSlot reserve(int slot, size_t count) override;
    void submit(int slot, const std::vector<ShadeRange>& ranges) override;
    void wait(int slot) override;

  private:
    struct Slot {
        std::unique_ptr<HostArray> inputs, results;
        size_t capacity = 0; // records
        size_t count = 0;    // records of the batch in the slot
        VkDescriptorPool descriptors = VK_NULL_HANDLE;
        std::vector<VkDescriptorSet> windows; // one per binding window of the buffers
        std::vector<VkBufferView> inputViews; // the inputs' texel view of each window
        VkCommandBuffer cmd = VK_NULL_HANDLE;
        VkFence fence = VK_NULL_HANDLE;
        bool inFlight = false;
        std::chrono::steady_clock::time_point submitted;
    };

    // The constructor's steps, in order.
    std::vector<std::string> chooseKernels(const RenderContext& ctx);
    void sizeWindows();
    void createCommandObjects();
    std::unique_ptr<HostArray> uploadTable(const void* data, size_t bytes, size_t texelBytes,
                                           const char* what);
    void uploadTables(const RenderContext& ctx);
    void buildPipelines(const std::vector<std::string>& kernels);

    void release();
    void releaseViews(Slot& slot);
    void grow(Slot& slot, size_t count);
    void recordDispatches(VkCommandBuffer cmd, const Slot& slot,
                          const std::vector<ShadeRange>& ranges);
    // `bound`: the set bound in `cmd` so far (VK_NULL_HANDLE: none), updated.
    void recordDispatch(VkCommandBuffer cmd, VkDescriptorSet set, VkDescriptorSet& bound,
                        uint32_t offset, uint32_t count);
    void submitAndWait(VkCommandBuffer cmd, VkFence fence);
    void readTimestamps();
    int pipelineFor(uint model) const;

    vk::Context& vk_;
    VkDevice device_;
    RenderParams params_;
    VulkanConfig config_;
    StageTimes& stages_;
    std::unique_ptr<HostArray> shaderTable_, emitterTable_, emitterCdf_, environment_;
    VkBufferView tableViews_[4] = {}; // bindings 0-3: the tables above as texel buffers
    std::unique_ptr<vk::ShadingPipelines> pipelines_;
    int modelPipeline_[kModelCount];
    int megakernel_ = -1;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkQueryPool queries_ = VK_NULL_HANDLE;
    uint32_t queriesUsed_ = 0; // written since the last read; the pool is reset when this is 0
    Slot slots_[kSlots];
    size_t windowRecords_ = 0; // records per binding window (within the device's limits)
    uint32_t maxGroupsX_ = 0, maxGroupsY_ = 0;
    bool timestamps_ = false;
    vk::KernelSpecialization spec_;

    // counters for --stats
    std::uint64_t dispatches_ = 0, submits_ = 0, maxBatch_ = 0, windowsUsed_ = 0,
                  twoDimensional_ = 0;
    std::uint64_t overlapped_ = 0; // submits made while the other slot's batch was still shading
    double submitSeconds_ = 0,
           waitSeconds_ = 0; // host time recording + submitting, and blocked in wait()
    std::uint64_t bufferBytes_ = 0;
    std::uint64_t bytesUp_ = 0, bytesDown_ = 0; // records written for and read back from the device
    // From the timestamps: device seconds copying in, shading and copying out; the device's idle
    // time between one submit's end and the next one's start (waiting on the host); and the
    // last submit's end tick, so a gap spanning a read of the query pool is counted too.
    double gpuUpload_ = 0, gpuDispatch_ = 0, gpuDownload_ = 0, gpuIdle_ = 0;
    std::uint64_t lastEndTick_ = 0;
    bool anyTick_ = false;
};

} // namespace spw::vk_engine
