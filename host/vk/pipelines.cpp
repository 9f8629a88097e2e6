#include "host/vk/pipelines.h"

#include "host/vk/check.h"
#include "host/vk/spirv.h"
#include "shared/shade_io.h"

#include <iterator>
#include <stdexcept>

namespace spw::vk {

ShadingPipelines::ShadingPipelines(const Context& context, const std::vector<std::string>& kernels,
                                   KernelSpecialization spec)
    : device_(context.device()) {
    try {
        VkDescriptorSetLayoutBinding bindings[kBindings]{};
        for (uint32_t b = 0; b < kBindings; ++b) {
            bindings[b].binding = b;
            bindings[b].descriptorType = bindingType(b);
            bindings[b].descriptorCount = 1;
            bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        }
        auto setInfo = zeroed<VkDescriptorSetLayoutCreateInfo>(
            VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
        setInfo.bindingCount = kBindings;
        setInfo.pBindings = bindings;
        SPW_VK_CHECK(vkCreateDescriptorSetLayout(device_, &setInfo, nullptr, &setLayout_));

        VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(ShadePush)};
        auto layoutInfo =
            zeroed<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
        layoutInfo.setLayoutCount = 1;
        layoutInfo.pSetLayouts = &setLayout_;
        layoutInfo.pushConstantRangeCount = 1;
        layoutInfo.pPushConstantRanges = &push;
        SPW_VK_CHECK(vkCreatePipelineLayout(device_, &layoutInfo, nullptr, &layout_));

        // Every constant is 32 bits wide (VkBool32 or uint).
        const uint32_t values[] = {spec.hasEmitters ? VK_TRUE : VK_FALSE,
                                   spec.textured ? VK_TRUE : VK_FALSE,
                                   spec.sampling,
                                   spec.strategy,
                                   spec.emitterKinds,
                                   spec.emissionMaps ? VK_TRUE : VK_FALSE};
        constexpr uint32_t kConstants = uint32_t(std::size(values));
        VkSpecializationMapEntry entries[kConstants];
        for (uint32_t i = 0; i < kConstants; ++i)
            entries[i] = {i, uint32_t(i * sizeof(uint32_t)), sizeof(uint32_t)};
        VkSpecializationInfo specInfo{kConstants, entries, sizeof(values), values};

        for (const std::string& name : kernels) {
            const SpirvKernel* spirv = findSpirvKernel(name);
            if (!spirv) throw std::runtime_error("no embedded SPIR-V kernel named '" + name + "'");
            auto moduleInfo =
                zeroed<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
            moduleInfo.codeSize = spirv->wordCount * sizeof(std::uint32_t);
            moduleInfo.pCode = spirv->words;
            VkShaderModule module = VK_NULL_HANDLE;
            SPW_VK_CHECK(vkCreateShaderModule(device_, &moduleInfo, nullptr, &module));
            auto info =
                zeroed<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
            info.stage = zeroed<VkPipelineShaderStageCreateInfo>(
                VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
            info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
            info.stage.module = module;
            info.stage.pName = "main";
            info.stage.pSpecializationInfo = &specInfo;
            info.layout = layout_;
            VkPipeline pipeline = VK_NULL_HANDLE;
            VkResult r =
                vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline);
            vkDestroyShaderModule(device_, module, nullptr); // the pipeline keeps what it needs
            SPW_VK_CHECK(r);
            pipelines_.push_back(pipeline);
            names_.push_back(name);
        }
    } catch (...) {
        release();
        throw;
    }
}

ShadingPipelines::~ShadingPipelines() {
    release();
}

void ShadingPipelines::release() {
    for (VkPipeline p : pipelines_)
        vkDestroyPipeline(device_, p, nullptr);
    pipelines_.clear();
    if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
    layout_ = VK_NULL_HANDLE;
    if (setLayout_) vkDestroyDescriptorSetLayout(device_, setLayout_, nullptr);
    setLayout_ = VK_NULL_HANDLE;
}

} // namespace spw::vk
