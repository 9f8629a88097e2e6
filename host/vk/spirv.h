// The kernels' SPIR-V, compiled from shaders/*.comp at build time and embedded by
// cmake/embed_spirv.cmake into a generated source in the build folder: the binary looks
// nothing up at run time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace spw::vk {

struct SpirvKernel {
    const char* name; // the .comp file's stem: a registry kernel name, or "megakernel"
    const std::uint32_t* words;
    size_t wordCount;
};

extern const SpirvKernel kSpirvKernels[];
extern const size_t kSpirvKernelCount;

// The embedded kernel of that name, or nullptr.
inline const SpirvKernel* findSpirvKernel(std::string_view name) {
    for (size_t i = 0; i < kSpirvKernelCount; ++i)
        if (name == kSpirvKernels[i].name) return &kSpirvKernels[i];
    return nullptr;
}

} // namespace spw::vk
