// libFuzzer harness: glTF files (.gltf and .glb) through the glTF loader, rendered as a scene.
// scripts/fuzz.sh builds and runs it.
#include "fuzz_targets.h"

#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string detail;
    if (spw::fuzz::gltf(data, size, &detail) == spw::fuzz::Outcome::Unexpected) {
        std::fprintf(stderr, "unexpected exception: %s\n", detail.c_str());
        std::abort();
    }
    return 0;
}
