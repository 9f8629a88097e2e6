#include "host/vk/vulkan_engine.h"

namespace spw::vk_engine {
namespace {

// Sorted by shader where the pipeline sorts (each model's range one dispatch), in object and
// texture order where images are read (neighbouring invocations share tiles); hit setup into a
// slot reads the hits through the order, so unsorted ones still have their misses moved out.
HitOrder vulkanHitOrder(const RenderContext& ctx, const PipelineConfig& pipeline) {
    return chooseHitOrder({pipeline.sortsHits(), true, false}, ctx.textures.active(),
                          ctx.params.environment != kNoEmitter);
}

} // namespace

VulkanShading::VulkanShading(const RenderContext& ctx, const PipelineConfig& pipeline,
                             vk::Context& context)
    : SlottedEngine(ctx, vulkanHitOrder(ctx, pipeline)), vk_(context), device_(context.device()),
      params_(ctx.params), config_(ctx.config.vulkan), stages_(ctx.stats.stages) {
    std::fill(std::begin(modelPipeline_), std::end(modelPipeline_), -1);
    try {
        const std::vector<std::string> kernels = chooseKernels(ctx);
        sizeWindows();
        createCommandObjects();
        uploadTables(ctx);
        buildPipelines(kernels);
    } catch (...) {
        release();
        throw;
    }
}

// What the scene needs: the models its meshes use, emitters, textures; the kernels to build
// (one per model used, or the megakernel) and what they are specialised on.
std::vector<std::string> VulkanShading::chooseKernels(const RenderContext& ctx) {
    const Scene& scene = ctx.scene;
    bool used[kModelCount] = {};
    bool textured = false;
    for (const Mesh& m : scene.meshes) {
        const Shader& sh = scene.shaders[size_t(m.shader)];
        if (sh.params.model >= kModelCount)
            throw std::runtime_error("shader '" + sh.typeName + "' has surface model " +
                                     std::to_string(sh.params.model) + ", which has no kernel");
        used[sh.params.model] = true;
        textured = textured || sh.texture >= 0 || !m.colours.empty();
    }
    spec_.hasEmitters = ctx.lights.view().emitterCount > 0;
    spec_.textured = textured;
    spec_.sampling = ctx.params.sampling;
    spec_.strategy = ctx.params.strategy;
    spec_.emitterKinds = 0;
    spec_.emissionMaps = false;
    for (const Emitter& e : ctx.lights.emitters()) {
        spec_.emitterKinds |= 1u << e.type;
        spec_.emissionMaps = spec_.emissionMaps || e.map != kNoEmissionMap;
    }
    std::vector<std::string> kernels;
    if (sortsByShader(hitOrder())) {
        for (const SurfaceModelInfo& m : kSurfaceModels)
            if (used[m.model]) {
                modelPipeline_[m.model] = int(kernels.size());
                kernels.push_back(m.kernel);
            }
    } else {
        megakernel_ = 0;
        kernels.push_back(kMegakernel);
    }
    return kernels;
}

// Binding windows: the input and result buffers are bound in ranges of windowRecords_ records:
// the inputs' within maxTexelBufferElements, the results' within maxStorageBufferRange, each
// starting at an offset aligned to minTexelBufferOffsetAlignment and
// minStorageBufferOffsetAlignment respectively.
void VulkanShading::sizeWindows() {
    const VkPhysicalDeviceLimits& limits = vk_.properties().limits;
    const VkDeviceSize texelRange = VkDeviceSize(limits.maxTexelBufferElements) * kTexelBytes;
    VkDeviceSize maxRange = std::min<VkDeviceSize>(limits.maxStorageBufferRange, texelRange);
    if (config_.maxBindingBytes) maxRange = std::min(maxRange, config_.maxBindingBytes);
    const size_t inputAlign =
        size_t(std::max<VkDeviceSize>(limits.minTexelBufferOffsetAlignment, 1));
    const size_t resultAlign =
        size_t(std::max<VkDeviceSize>(limits.minStorageBufferOffsetAlignment, 1));
    const size_t step = std::lcm(std::lcm(sizeof(ShadeInput), inputAlign) / sizeof(ShadeInput),
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
}

// The command pool, a command buffer and fence per slot, and the timestamp queries.
void VulkanShading::createCommandObjects() {
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
}

// One of the scene's tables in a texel buffer, checked against maxTexelBufferElements.
std::unique_ptr<HostArray> VulkanShading::uploadTable(const void* data, size_t bytes,
                                                      size_t texelBytes, const char* what) {
    const uint32_t maxTexels = vk_.properties().limits.maxTexelBufferElements;
    if (bytes / texelBytes > maxTexels)
        throw std::runtime_error(std::string("the scene's ") + what + " table (" +
                                 std::to_string(bytes / texelBytes) +
                                 " texels) exceeds the device's maxTexelBufferElements (" +
                                 std::to_string(maxTexels) + ")");
    auto a =
        std::make_unique<HostArray>(vk_, bytes, HostArray::Direction::Upload, config_.forceStaging);
    if (bytes) std::memcpy(a->host(), data, bytes);
    bufferBytes_ += a->size();
    return a;
}

// The scene's tables, uploaded once: shaders, emitters, the emitters' CDF and light tree, the
// environment.
void VulkanShading::uploadTables(const RenderContext& ctx) {
    const auto start = std::chrono::steady_clock::now();
    const SceneView view = ctx.lights.view();
    const SceneLights& lights = ctx.lights;
    static_assert(sizeof(ShaderParams) % kTexelBytes == 0 && sizeof(Emitter) % kTexelBytes == 0,
                  "the kernels fetch ShaderParams and Emitter as whole texels");
    shaderTable_ = uploadTable(view.shaders, ctx.scene.shaders.size() * sizeof(ShaderParams),
                               kTexelBytes, "shader");
    emitterTable_ = uploadTable(view.emitters, lights.emitters().size() * sizeof(Emitter),
                                kTexelBytes, "emitter");
    emitterCdf_ = uploadTable(view.emitterCdf, lights.emitterTable().size() * sizeof(float),
                              sizeof(float), "emitter CDF and light tree");
    // The environment's map and CDFs and the emission maps; without them, 16 bytes are bound.
    environment_ = uploadTable(lights.lightData().data(), lights.lightData().size() * sizeof(float),
                               sizeof(float), "light data");
    const HostArray* tables[4] = {shaderTable_.get(), emitterTable_.get(), emitterCdf_.get(),
                                  environment_.get()};
    const VkFormat formats[4] = {VK_FORMAT_R32G32B32A32_UINT, VK_FORMAT_R32G32B32A32_UINT,
                                 VK_FORMAT_R32_UINT, VK_FORMAT_R32_UINT};
    for (int b = 0; b < 4; ++b)
        tableViews_[b] = makeTexelView(device_, tables[b]->device(), formats[b], 0, VK_WHOLE_SIZE);
    if (shaderTable_->staged()) {
        VkCommandBuffer cmd = slots_[0].cmd;
        auto begin = zeroed<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        SPW_VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
        for (const HostArray* a : tables)
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
void VulkanShading::buildPipelines(const std::vector<std::string>& kernels) {
    const auto start = std::chrono::steady_clock::now();
    pipelines_ = std::make_unique<vk::ShadingPipelines>(vk_, kernels, spec_);
    Slot& s = slots_[0];
    grow(s, kMinCapacity);
    auto begin = zeroed<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
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

} // namespace spw::vk_engine
