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
// What a render fixes for all its hits, given to the kernels as specialisation constants so that
// the driver drops the code a scene does not use (shaders/shade_kernel.glsl).
struct KernelSpecialization {
    bool hasEmitters = true;     // constant_id 0: emission and next-event estimation
    bool textured = true;        // constant_id 1: per-hit albedo resolved by the host
    uint32_t sampling = 0;       // constant_id 2: RenderParams::sampling
    uint32_t strategy = 0;       // constant_id 3: RenderParams::strategy
    uint32_t emitterKinds = ~0u; // constant_id 4: bit 1 << kEmitter* for each kind in the scene
    bool emissionMaps = true;    // constant_id 5: an emitter has an emission map
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

    // Bindings 0-4 (the scene's tables and the inputs) are uniform texel buffers, 5 (the results)
    // a storage buffer: shaders/shade_kernel.glsl says why.
    static constexpr uint32_t kBindings = 6;
    static constexpr uint32_t kResultsBinding = 5;
    static constexpr VkDescriptorType bindingType(uint32_t binding) {
        return binding == kResultsBinding ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                          : VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    }

  private:
    void release();

    VkDevice device_;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    std::vector<VkPipeline> pipelines_;
    std::vector<std::string> names_;
};

} // namespace spw::vk
