#include "host/vk/vulkan_engine.h"

#include "host/scene/emitter_kinds.h"

#include <algorithm>
#include <cctype>

namespace spw::vk_engine {

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
    bytesUp_ += s.count * sizeof(ShadeInput);
    bytesDown_ += s.count * sizeof(ShadeResult);
    submitSeconds_ += seconds(start);
    ++submits_;
    // The other slot's batch still shading now: its shading overlapped this batch's traversal.
    for (const Slot& other : slots_)
        if (&other != &s && other.inFlight &&
            vkGetFenceStatus(device_, other.fence) == VK_NOT_READY)
            ++overlapped_;
}

void VulkanShading::wait(int slot) {
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
    const double ns = vk_.timestampPeriodNs() * 1e-9;
    double upload = 0, dispatch = 0, download = 0;
    for (uint32_t i = 0; i < queriesUsed_; i += kTimestamps) {
        upload += double(t[i + 1] - t[i]) * ns;
        dispatch += double(t[i + 2] - t[i + 1]) * ns;
        download += double(t[i + 3] - t[i + 2]) * ns;
        // Submits run in order on the one queue: a start after the last end is the device idle.
        if (anyTick_ && t[i] > lastEndTick_) gpuIdle_ += double(t[i] - lastEndTick_) * ns;
        lastEndTick_ = std::max(lastEndTick_, t[i + 3]);
        anyTick_ = true;
    }
    stages_.add("upload", upload);
    stages_.add("dispatch", dispatch);
    stages_.add("download", download);
    gpuUpload_ += upload;
    gpuDispatch_ += dispatch;
    gpuDownload_ += download;
    queriesUsed_ = 0;
}

void VulkanShading::publishStats(RenderStats& stats) {
    for (const Slot& s : slots_)
        if (s.inFlight)
            throw std::logic_error("VulkanShading::publishStats with a batch in flight");
    SlottedEngine::publishStats(stats);
    readTimestamps();
    const vk::DeviceInfo& d = vk_.info();
    nlohmann::json v;
    v["device"] = d.name;
    v["device_type"] = d.type;
    v["driver"] = d.driver;
    v["api"] = d.api;
    v["pipelines"] = pipelines_->names();
    nlohmann::json kinds = nlohmann::json::array();
    for (const EmitterKindInfo& k : kEmitterKindTable)
        if (spec_.emitterKinds & (1u << k.kind)) {
            std::string name = k.name;
            name[0] = char(std::tolower(name[0]));
            kinds.push_back(name);
        }
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
    v["bytes_uploaded"] = bytesUp_;
    v["bytes_downloaded"] = bytesDown_;
    if (timestamps_) // device time, from the timestamp queries around each submit's commands
        v["gpu_seconds"] = {
            {"upload", gpuUpload_},
            {"dispatch", gpuDispatch_},
            {"download", gpuDownload_},
            {"per_dispatch", dispatches_ ? gpuDispatch_ / double(dispatches_) : 0.0},
            {"idle_between_submits", gpuIdle_}};
    v["validation"] = vk_.validation();
    v["validation_messages"] = vk_.validationMessages();
    stats.extra["vulkan"] = v;
}

} // namespace spw::vk_engine

namespace spw {

std::unique_ptr<ShadingEngine>
makeVulkanShading(const RenderContext& ctx, const PipelineConfig& pipeline, vk::Context& context) {
    return std::make_unique<vk_engine::VulkanShading>(ctx, pipeline, context);
}

} // namespace spw
