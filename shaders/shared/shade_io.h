// What crosses between the host and a shading kernel, declared once for both compilers: the
// per-hit input record, and the push constants of one dispatch. (The per-hit output is
// ShadeResult in types.h: the shadow ray with its pending contribution and the continuation ray,
// which the host traces and bins. Rays themselves never cross: Embree traces them on the host.)
// The C++ layout is pinned in host/vk/shared_layout.cpp; kernels read these through
// GL_EXT_scalar_block_layout, which packs them exactly as C++ over glm does (vec3 = 12 bytes,
// 4-byte alignment), so no field needs hand padding beyond what is written here.
#ifndef SPILLWAY_SHARED_SHADE_IO_H
#define SPILLWAY_SHARED_SHADE_IO_H
#include "types.h"

SHARED_BEGIN

// One hit as the shading stage receives it, in hit-sorted order.
struct ShadeInput {
    SurfaceHit hit;
    PathState path;
    vec3 rayDir;
    uint pad0; // to 128 bytes, the 8 texels a kernel fetches it in
};

// Threads per workgroup of every shading kernel.
const uint kShadeWorkgroupSize = 64u;

// Push constants of one dispatch: the render's parameters and the range of records it shades,
// relative to the bound window of the input and output buffers.
struct ShadePush {
    RenderParams params;
    uint offset; // first record of the range within the bound window
    uint count;  // records in the range
    uint pad0;
};

SHARED_END
#endif
