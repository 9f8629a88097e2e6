// The shading pipelines: one compute pipeline per kernel the scene needs, all sharing one
// descriptor-set layout (0 shader table, 1 emitters, 2 emitter CDF, 3 environment map and CDFs,
// 4 inputs, 5 results) and
// one push-constant range (ShadePush). Kernels come from the embedded SPIR-V; specialisation
// constants drop the code paths the scene does not need (shaders/shade_kernel.glsl lists them).
#pragma once

#include "host/vk/context.h"

#include <vulkan/vulkan.h>

#include <string>
#include <vector>

namespace spw::vk {

// Values of the kernels' specialisation constants.
struct KernelSpecialization {
    bool hasEmitters = true; // constant_id 0: emission and next-event estimation
    bool textured = true;    // constant_id 1: per-hit albedo resolved by the host
};

class ShadingPipelines {
  public:
    // One pipeline per name in `kernels` (a registry kernel, or kMegakernel). Throws when a
    // kernel is not embedded.
    ShadingPipelines(const Context& context, const std::vector<std::string>& kernels,
                     KernelSpecialization spec);
    ~ShadingPipelines();
    ShadingPipelines(const ShadingPipelines&) = delete;
    ShadingPipelines& operator=(const ShadingPipelines&) = delete;

    VkDescriptorSetLayout setLayout() const { return setLayout_; }
    VkPipelineLayout layout() const { return layout_; }
    size_t size() const { return pipelines_.size(); }
    VkPipeline pipeline(size_t i) const { return pipelines_[i]; }
    const std::vector<std::string>& names() const { return names_; }

    static constexpr uint32_t kBindings = 6;

  private:
    void release();

    VkDevice device_;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    std::vector<VkPipeline> pipelines_;
    std::vector<std::string> names_;
};

} // namespace spw::vk
