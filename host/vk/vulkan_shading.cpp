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

namespace spw {
namespace {

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

double seconds(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void barrier(VkCommandBuffer cmd, VkPipelineStageFlags src, VkAccessFlags srcAccess,
             VkPipelineStageFlags dst, VkAccessFlags dstAccess) {
    auto b = zeroed<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cmd, src, dst, 0, 1, &b, 0, nullptr, 0, nullptr);
}

// A view of `range` bytes of `buffer` from `offset` as texels of `format`, for a uniform texel
// buffer binding.
VkBufferView makeTexelView(VkDevice device, VkBuffer buffer, VkFormat format, VkDeviceSize offset,
                           VkDeviceSize range) {
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

class VulkanShading : public ShadingEngine {
  public:
    VulkanShading(const RenderContext& ctx, const PipelineConfig& pipeline, vk::Context& context);
    ~VulkanShading() override;

    void beginIteration(uint iteration) override { params_.iteration = iteration; }
    int slots() const override { return int(kSlots); }
    ShadeSlot reserve(int slot, size_t count) override;
    void submit(int slot, const std::vector<ShadeRange>& ranges) override;
    void finish(int slot) override;
    void publishStats(RenderStats& stats) override;

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
           waitSeconds_ = 0; // host time recording + submitting, and blocked in finish()
    std::uint64_t bufferBytes_ = 0;
};

VulkanShading::VulkanShading(const RenderContext& ctx, const PipelineConfig& pipeline,
                             vk::Context& context)
    : vk_(context), device_(context.device()), params_(ctx.params), config_(ctx.config.vulkan),
      stages_(ctx.stats.stages) {
    std::fill(std::begin(modelPipeline_), std::end(modelPipeline_), -1);
    try {
        const VkPhysicalDeviceLimits& limits = vk_.properties().limits;
        const SceneView view = ctx.lights.view();
        const Scene& scene = ctx.scene;

        // What the scene needs: the models its meshes use, emitters, textures.
        bool used[kModelCount] = {};
        bool textured = false;
        for (const Mesh& m : scene.meshes) {
            const Shader& sh = scene.shaders[size_t(m.shader)];
            if (sh.params.model >= kModelCount)
                throw std::runtime_error("shader '" + sh.typeName + "' has surface model " +
                                         std::to_string(sh.params.model) + ", which has no kernel");
            used[sh.params.model] = true;
            textured = textured || sh.texture >= 0;
        }
        spec_.hasEmitters = view.emitterCount > 0;
        spec_.textured = textured;
        spec_.sampling = ctx.params.sampling;
        spec_.strategy = ctx.params.strategy;
        spec_.emitterKinds = 0;
        for (const Emitter& e : ctx.lights.emitters())
            spec_.emitterKinds |= 1u << e.type;
        std::vector<std::string> kernels;
        if (pipeline.sortsHits()) {
            for (const SurfaceModelInfo& m : kSurfaceModels)
                if (used[m.model]) {
                    modelPipeline_[m.model] = int(kernels.size());
                    kernels.push_back(m.kernel);
                }
        } else {
            megakernel_ = 0;
            kernels.push_back(kMegakernel);
        }

        // Binding windows: the input and result buffers are bound in ranges of windowRecords_
        // records: the inputs' within maxTexelBufferElements, the results' within
        // maxStorageBufferRange, each starting at an offset aligned to
        // minTexelBufferOffsetAlignment and minStorageBufferOffsetAlignment respectively.
        const VkDeviceSize texelRange = VkDeviceSize(limits.maxTexelBufferElements) * kTexelBytes;
        VkDeviceSize maxRange = std::min<VkDeviceSize>(limits.maxStorageBufferRange, texelRange);
        if (config_.maxBindingBytes) maxRange = std::min(maxRange, config_.maxBindingBytes);
        const size_t inputAlign =
            size_t(std::max<VkDeviceSize>(limits.minTexelBufferOffsetAlignment, 1));
        const size_t resultAlign =
            size_t(std::max<VkDeviceSize>(limits.minStorageBufferOffsetAlignment, 1));
        const size_t step =
            std::lcm(std::lcm(sizeof(ShadeInput), inputAlign) / sizeof(ShadeInput),
                     std::lcm(sizeof(ShadeResult), resultAlign) / sizeof(ShadeResult));
        const size_t largest = std::max(sizeof(ShadeInput), sizeof(ShadeResult));
        windowRecords_ = size_t(maxRange / largest) / step * step;
        if (windowRecords_ == 0)
            throw std::runtime_error("the device's maxStorageBufferRange or "
                                     "maxTexelBufferElements holds no shading record");
        maxGroupsX_ = config_.maxGroupsX
                          ? std::min(config_.maxGroupsX, limits.maxComputeWorkGroupCount[0])
                          : limits.maxComputeWorkGroupCount[0];
        maxGroupsY_ = limits.maxComputeWorkGroupCount[1];
        timestamps_ = vk_.timestampPeriodNs() > 0.0;

        auto poolInfo = zeroed<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
        poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        poolInfo.queueFamilyIndex = vk_.queueFamily();
        SPW_VK_CHECK(vkCreateCommandPool(device_, &poolInfo, nullptr, &pool_));
        if (timestamps_) {
            auto q = zeroed<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
            q.queryType = VK_QUERY_TYPE_TIMESTAMP;
            q.queryCount = kQueryCapacity;
            SPW_VK_CHECK(vkCreateQueryPool(device_, &q, nullptr, &queries_));
        }
        for (Slot& s : slots_) {
            auto alloc =
                zeroed<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
            alloc.commandPool = pool_;
            alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
            alloc.commandBufferCount = 1;
            SPW_VK_CHECK(vkAllocateCommandBuffers(device_, &alloc, &s.cmd));
            auto fenceInfo = zeroed<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
            SPW_VK_CHECK(vkCreateFence(device_, &fenceInfo, nullptr, &s.fence));
        }

        // The scene's tables, uploaded once.
        {
            const auto start = std::chrono::steady_clock::now();
            auto table = [&](const void* data, size_t bytes, size_t texelBytes, const char* what) {
                if (bytes / texelBytes > limits.maxTexelBufferElements)
                    throw std::runtime_error(
                        std::string("the scene's ") + what + " table (" +
                        std::to_string(bytes / texelBytes) +
                        " texels) exceeds the device's maxTexelBufferElements (" +
                        std::to_string(limits.maxTexelBufferElements) + ")");
                auto a = std::make_unique<HostArray>(vk_, bytes, HostArray::Direction::Upload,
                                                     config_.forceStaging);
                if (bytes) std::memcpy(a->host(), data, bytes);
                bufferBytes_ += a->size();
                return a;
            };
            static_assert(sizeof(ShaderParams) % kTexelBytes == 0 &&
                              sizeof(Emitter) % kTexelBytes == 0,
                          "the kernels fetch ShaderParams and Emitter as whole texels");
            shaderTable_ = table(view.shaders, scene.shaders.size() * sizeof(ShaderParams),
                                 kTexelBytes, "shader");
            const SceneLights& lights = ctx.lights;
            emitterTable_ = table(view.emitters, lights.emitters().size() * sizeof(Emitter),
                                  kTexelBytes, "emitter");
            emitterCdf_ = table(view.emitterCdf, view.emitterCount * sizeof(float), sizeof(float),
                                "emitter CDF");
            // The environment's map and CDFs; a constant environment (or none) binds 16 bytes.
            environment_ = table(lights.environmentData().data(),
                                 lights.environmentData().size() * sizeof(float), sizeof(float),
                                 "environment");
            const HostArray* tables[4] = {shaderTable_.get(), emitterTable_.get(),
                                          emitterCdf_.get(), environment_.get()};
            const VkFormat formats[4] = {VK_FORMAT_R32G32B32A32_UINT, VK_FORMAT_R32G32B32A32_UINT,
                                         VK_FORMAT_R32_UINT, VK_FORMAT_R32_UINT};
            for (int b = 0; b < 4; ++b)
                tableViews_[b] =
                    makeTexelView(device_, tables[b]->device(), formats[b], 0, VK_WHOLE_SIZE);
            if (shaderTable_->staged()) {
                VkCommandBuffer cmd = slots_[0].cmd;
                auto begin =
                    zeroed<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
                begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
                SPW_VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
                for (const HostArray* a : {shaderTable_.get(), emitterTable_.get(),
                                           emitterCdf_.get(), environment_.get()})
                    a->recordCopy(cmd, a->size());
                barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
                SPW_VK_CHECK(vkEndCommandBuffer(cmd));
                submitAndWait(cmd, slots_[0].fence);
            }
            stages_.add("upload", seconds(start));
        }

        // Pipelines, then one empty dispatch each: drivers such as lavapipe compile at the first
        // dispatch, and that belongs here, not in the first batch's timing.
        {
            const auto start = std::chrono::steady_clock::now();
            pipelines_ = std::make_unique<vk::ShadingPipelines>(vk_, kernels, spec_);
            Slot& s = slots_[0];
            grow(s, kMinCapacity);
            auto begin =
                zeroed<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
            begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
            SPW_VK_CHECK(vkBeginCommandBuffer(s.cmd, &begin));
            VkDescriptorSet bound = VK_NULL_HANDLE;
            for (size_t i = 0; i < pipelines_->size(); ++i) {
                vkCmdBindPipeline(s.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_->pipeline(i));
                recordDispatch(s.cmd, s.windows[0], bound, 0, 0);
            }
            SPW_VK_CHECK(vkEndCommandBuffer(s.cmd));
            submitAndWait(s.cmd, s.fence);
            stages_.add("pipelines", seconds(start));
        }
    } catch (...) {
        release();
        throw;
    }
}

VulkanShading::~VulkanShading() {
    release();
}

void VulkanShading::release() {
    if (device_) vkDeviceWaitIdle(device_);
    for (Slot& s : slots_) {
        if (s.fence) vkDestroyFence(device_, s.fence, nullptr);
        if (s.descriptors) vkDestroyDescriptorPool(device_, s.descriptors, nullptr);
        releaseViews(s);
        s = Slot{};
    }
    for (VkBufferView& v : tableViews_) {
        if (v) vkDestroyBufferView(device_, v, nullptr);
        v = VK_NULL_HANDLE;
    }
    if (queries_) vkDestroyQueryPool(device_, queries_, nullptr);
    queries_ = VK_NULL_HANDLE;
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr); // frees the command buffers
    pool_ = VK_NULL_HANDLE;
    pipelines_.reset();
    shaderTable_.reset();
    emitterTable_.reset();
    emitterCdf_.reset();
    environment_.reset();
}

void VulkanShading::submitAndWait(VkCommandBuffer cmd, VkFence fence) {
    auto submit = zeroed<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    SPW_VK_CHECK(vkQueueSubmit(vk_.queue(), 1, &submit, fence));
    SPW_VK_CHECK(vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX));
    SPW_VK_CHECK(vkResetFences(device_, 1, &fence));
}

void VulkanShading::releaseViews(Slot& s) {
    for (VkBufferView v : s.inputViews)
        vkDestroyBufferView(device_, v, nullptr);
    s.inputViews.clear();
}

// Sizes the slot's buffers to at least `count` records (the next power of two: batches are
// 2^e rays) and writes one descriptor set per binding window.
void VulkanShading::grow(Slot& s, size_t count) {
    if (s.inputs && count <= s.capacity) return;
    size_t capacity = kMinCapacity;
    while (capacity < count)
        capacity *= 2;
    if (s.descriptors) vkDestroyDescriptorPool(device_, s.descriptors, nullptr);
    s.descriptors = VK_NULL_HANDLE;
    s.windows.clear();
    releaseViews(s);
    if (s.inputs) bufferBytes_ -= s.inputs->size() + s.results->size();
    s.inputs.reset();
    s.results.reset();
    s.capacity = 0;
    s.inputs = std::make_unique<HostArray>(vk_, capacity * sizeof(ShadeInput),
                                           HostArray::Direction::Upload, config_.forceStaging);
    s.results = std::make_unique<HostArray>(vk_, capacity * sizeof(ShadeResult),
                                            HostArray::Direction::Download, config_.forceStaging);
    bufferBytes_ += s.inputs->size() + s.results->size();
    s.capacity = capacity;

    const uint32_t windows = uint32_t((capacity + windowRecords_ - 1) / windowRecords_);
    const VkDescriptorPoolSize sizes[2] = {
        {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, windows * (vk::ShadingPipelines::kBindings - 1)},
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, windows}};
    auto poolInfo =
        zeroed<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    poolInfo.maxSets = windows;
    poolInfo.poolSizeCount = 2;
    poolInfo.pPoolSizes = sizes;
    SPW_VK_CHECK(vkCreateDescriptorPool(device_, &poolInfo, nullptr, &s.descriptors));
    std::vector<VkDescriptorSetLayout> layouts(windows, pipelines_->setLayout());
    auto alloc =
        zeroed<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    alloc.descriptorPool = s.descriptors;
    alloc.descriptorSetCount = windows;
    alloc.pSetLayouts = layouts.data();
    s.windows.resize(windows);
    SPW_VK_CHECK(vkAllocateDescriptorSets(device_, &alloc, s.windows.data()));
    for (uint32_t w = 0; w < windows; ++w) {
        const size_t first = size_t(w) * windowRecords_;
        const size_t records = std::min(windowRecords_, capacity - first);
        s.inputViews.push_back(
            makeTexelView(device_, s.inputs->device(), VK_FORMAT_R32G32B32A32_UINT,
                          first * sizeof(ShadeInput), records * sizeof(ShadeInput)));
        const VkBufferView views[5] = {tableViews_[0], tableViews_[1], tableViews_[2],
                                       tableViews_[3], s.inputViews.back()};
        const VkDescriptorBufferInfo results{s.results->device(), first * sizeof(ShadeResult),
                                             records * sizeof(ShadeResult)};
        VkWriteDescriptorSet writes[vk::ShadingPipelines::kBindings];
        for (uint32_t b = 0; b < vk::ShadingPipelines::kBindings; ++b) {
            writes[b] = zeroed<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
            writes[b].dstSet = s.windows[w];
            writes[b].dstBinding = b;
            writes[b].descriptorCount = 1;
            writes[b].descriptorType = vk::ShadingPipelines::bindingType(b);
            if (b == vk::ShadingPipelines::kResultsBinding)
                writes[b].pBufferInfo = &results;
            else
                writes[b].pTexelBufferView = &views[b];
        }
        vkUpdateDescriptorSets(device_, vk::ShadingPipelines::kBindings, writes, 0, nullptr);
    }
}

ShadeSlot VulkanShading::reserve(int slot, size_t count) {
    Slot& s = slots_[slot];
    if (s.inFlight)
        throw std::logic_error("VulkanShading::reserve: the slot is still being shaded");
    grow(s, count);
    s.count = count;
    maxBatch_ = std::max<std::uint64_t>(maxBatch_, count);
    return {static_cast<ShadeInput*>(s.inputs->host()),
            static_cast<const ShadeResult*>(s.results->host())};
}

int VulkanShading::pipelineFor(uint model) const {
    const int p = model == kMixedModels ? megakernel_
                  : model < kModelCount ? modelPipeline_[model]
                                        : -1;
    if (p < 0)
        throw std::logic_error(model == kMixedModels
                                   ? "unsorted hits but no megakernel pipeline"
                                   : "no pipeline for surface model " + std::to_string(model));
    return p;
}

// One dispatch of `count` records from `offset` in the bound window: 1D, or 2D when the range
// needs more workgroups than one dimension allows.
// The set is bound only when it changes: binding another pipeline of the same layout keeps it.
void VulkanShading::recordDispatch(VkCommandBuffer cmd, VkDescriptorSet set, VkDescriptorSet& bound,
                                   uint32_t offset, uint32_t count) {
    if (set != bound) {
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_->layout(), 0, 1,
                                &set, 0, nullptr);
        bound = set;
    }
    ShadePush push{};
    push.params = params_;
    push.offset = offset;
    push.count = count;
    vkCmdPushConstants(cmd, pipelines_->layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push),
                       &push);
    const std::uint64_t groups = std::max<std::uint64_t>(
        1, (std::uint64_t(count) + kShadeWorkgroupSize - 1) / kShadeWorkgroupSize);
    const uint32_t gx = uint32_t(std::min<std::uint64_t>(groups, maxGroupsX_));
    const uint32_t gy = uint32_t((groups + gx - 1) / gx);
    if (gy > 1) ++twoDimensional_;
    vkCmdDispatch(cmd, gx, gy, 1);
}

void VulkanShading::recordDispatches(VkCommandBuffer cmd, const Slot& s,
                                     const std::vector<ShadeRange>& ranges) {
    // Records one dispatch may cover: both grid dimensions full.
    const std::uint64_t perDispatch =
        std::uint64_t(maxGroupsX_) * maxGroupsY_ * kShadeWorkgroupSize;
    int bound = -1;
    VkDescriptorSet boundSet = VK_NULL_HANDLE;
    for (const ShadeRange& r : ranges) {
        if (r.count == 0) continue;
        const int p = pipelineFor(r.model);
        if (p != bound) {
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_->pipeline(size_t(p)));
            bound = p;
        }
        // A range crossing a binding window is split there.
        size_t begin = r.begin;
        const size_t end = r.begin + r.count;
        while (begin < end) {
            const size_t w = begin / windowRecords_;
            const size_t windowEnd = std::min(end, (w + 1) * windowRecords_);
            const size_t count = size_t(std::min<std::uint64_t>(windowEnd - begin, perDispatch));
            recordDispatch(cmd, s.windows[w], boundSet, uint32_t(begin - w * windowRecords_),
                           uint32_t(count));
            ++dispatches_;
            if (w > 0) windowsUsed_ = std::max<std::uint64_t>(windowsUsed_, w + 1);
            begin += count;
        }
    }
}

void VulkanShading::submit(int slot, const std::vector<ShadeRange>& ranges) {
    Slot& s = slots_[slot];
    if (s.count == 0) return;
    const auto start = std::chrono::steady_clock::now();
    if (timestamps_ && queriesUsed_ + kTimestamps > kQueryCapacity) {
        for (const Slot& other : slots_) // the pool is full: let the batch in flight end first
            if (other.inFlight)
                SPW_VK_CHECK(vkWaitForFences(device_, 1, &other.fence, VK_TRUE, UINT64_MAX));
        readTimestamps();
    }
    const uint32_t q = queriesUsed_;
    VkCommandBuffer cmd = s.cmd;
    SPW_VK_CHECK(vkResetCommandBuffer(cmd, 0));
    auto begin = zeroed<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    SPW_VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
    if (timestamps_) {
        if (q == 0) vkCmdResetQueryPool(cmd, queries_, 0, kQueryCapacity);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, q);
        queriesUsed_ += kTimestamps;
    }
    // Host writes before vkQueueSubmit are visible to the device without a barrier.
    if (s.inputs->staged()) {
        s.inputs->recordCopy(cmd, s.count * sizeof(ShadeInput));
        barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    }
    if (timestamps_)
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, q + 1);
    recordDispatches(cmd, s, ranges);
    if (timestamps_)
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, q + 2);
    if (s.results->staged()) {
        barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        s.results->recordCopy(cmd, s.count * sizeof(ShadeResult));
        barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    } else {
        barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    }
    if (timestamps_)
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, q + 3);
    SPW_VK_CHECK(vkEndCommandBuffer(cmd));
    auto info = zeroed<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    info.commandBufferCount = 1;
    info.pCommandBuffers = &cmd;
    SPW_VK_CHECK(vkQueueSubmit(vk_.queue(), 1, &info, s.fence));
    s.inFlight = true;
    s.submitted = std::chrono::steady_clock::now();
    submitSeconds_ += seconds(start);
    ++submits_;
    // The other slot's batch still shading now: its shading overlapped this batch's traversal.
    for (const Slot& other : slots_)
        if (&other != &s && other.inFlight &&
            vkGetFenceStatus(device_, other.fence) == VK_NOT_READY)
            ++overlapped_;
}

void VulkanShading::finish(int slot) {
    Slot& s = slots_[slot];
    if (!s.inFlight) return;
    const auto start = std::chrono::steady_clock::now();
    SPW_VK_CHECK(vkWaitForFences(device_, 1, &s.fence, VK_TRUE, UINT64_MAX));
    waitSeconds_ += seconds(start);
    SPW_VK_CHECK(vkResetFences(device_, 1, &s.fence));
    s.inFlight = false;
    // No timestamps on this queue: the whole submit counts as dispatch, seen from the host.
    if (!timestamps_) stages_.add("dispatch", seconds(s.submitted));
}

// Adds up the timestamps written since the last read; no batch may be in flight.
void VulkanShading::readTimestamps() {
    if (queriesUsed_ == 0) return;
    std::vector<std::uint64_t> t(queriesUsed_);
    SPW_VK_CHECK(vkGetQueryPoolResults(
        device_, queries_, 0, queriesUsed_, t.size() * sizeof(std::uint64_t), t.data(),
        sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    double upload = 0, dispatch = 0, download = 0;
    for (uint32_t i = 0; i < queriesUsed_; i += kTimestamps) {
        upload += double(t[i + 1] - t[i]);
        dispatch += double(t[i + 2] - t[i + 1]);
        download += double(t[i + 3] - t[i + 2]);
    }
    const double ns = vk_.timestampPeriodNs() * 1e-9;
    stages_.add("upload", upload * ns);
    stages_.add("dispatch", dispatch * ns);
    stages_.add("download", download * ns);
    queriesUsed_ = 0;
}

void VulkanShading::publishStats(RenderStats& stats) {
    for (const Slot& s : slots_)
        if (s.inFlight)
            throw std::logic_error("VulkanShading::publishStats with a batch in flight");
    readTimestamps();
    const vk::DeviceInfo& d = vk_.info();
    nlohmann::json v;
    v["device"] = d.name;
    v["device_type"] = d.type;
    v["driver"] = d.driver;
    v["api"] = d.api;
    v["pipelines"] = pipelines_->names();
    nlohmann::json kinds = nlohmann::json::array();
    const char* kindNames[] = {"triangle", "point", "environment"};
    for (uint k = 0; k < 3; ++k)
        if (spec_.emitterKinds & (1u << k)) kinds.push_back(kindNames[k]);
    v["specialization"] = {{"emitters", spec_.hasEmitters},
                           {"textures", spec_.textured},
                           {"sampler", spec_.sampling == kSamplerSobol ? "sobol" : "pcg"},
                           {"strategy", spec_.strategy == kStrategyMis     ? "mis"
                                        : spec_.strategy == kStrategyLight ? "light"
                                                                           : "bsdf"},
                           {"emitter_kinds", kinds}};
    v["memory"] = {{"inputs", slots_[0].inputs->mode()},
                   {"results", slots_[0].results->mode()},
                   {"scene", shaderTable_->mode()}};
    v["buffer_bytes"] = bufferBytes_;
    v["batch_slots"] = kSlots;
    v["submits_overlapping_shading"] = overlapped_;
    v["host_submit_seconds"] = submitSeconds_;
    v["host_wait_seconds"] = waitSeconds_;
    v["largest_batch_hits"] = maxBatch_;
    v["submits"] = submits_;
    v["dispatches"] = dispatches_;
    v["dispatches_2d"] = twoDimensional_;
    v["binding_window_records"] = windowRecords_;
    v["binding_windows_used"] = std::max<std::uint64_t>(windowsUsed_, 1);
    v["timestamps"] = timestamps_;
    v["validation"] = vk_.validation();
    v["validation_messages"] = vk_.validationMessages();
    stats.extra["vulkan"] = v;
}

} // namespace

std::unique_ptr<ShadingEngine>
makeVulkanShading(const RenderContext& ctx, const PipelineConfig& pipeline, vk::Context& context) {
    return std::make_unique<VulkanShading>(ctx, pipeline, context);
}

} // namespace spw
