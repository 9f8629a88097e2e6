// libFuzzer harness: scene files (YAML, and the OBJ they reference). scripts/fuzz.sh builds and
// runs it.
#include "fuzz_targets.h"

#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string detail;
    if (spw::fuzz::scene(data, size, &detail) == spw::fuzz::Outcome::Unexpected) {
        std::fprintf(stderr, "unexpected exception: %s\n", detail.c_str());
        std::abort();
    }
    return 0;
}
