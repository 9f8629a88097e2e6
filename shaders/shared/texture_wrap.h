// What a texture coordinate outside [0, 1] reads (glTF's sampler wrap modes), for a filter that
// repeats: the host's texture lookups (host/textures/textures.cpp) and the kernels' emission maps
// (shared/emission_map.h) both wrap their coordinates through this one function.
#ifndef SPILLWAY_SHARED_TEXTURE_WRAP_H
#define SPILLWAY_SHARED_TEXTURE_WRAP_H
#include "compat.h"

SHARED_BEGIN

const uint kWrapRepeat = 0u; // the image repeated
const uint kWrapClamp = 1u;  // its edge texels
const uint kWrapMirror = 2u; // the image mirrored about the integers

// Coordinate x on an axis of n texels as `mode` reads it through a periodic bilinear filter:
// repeat leaves it; mirror folds it about the integers; mirror and clamp keep it within half a
// texel of the edges, where the filter reads the edge texel alone. Exact at the finest MIP
// level; a coarser level's wider texels still blend a little of the far edge in.
SHARED_FN float wrapCoordinate(float x, uint mode, uint n) {
    if (mode == kWrapRepeat) return x;
    if (mode == kWrapMirror) {
        x -= 2.0f * floor(0.5f * x);
        if (x > 1.0f) x = 2.0f - x;
    }
    float halfTexel = 0.5f / float(n);
    return clamp(x, halfTexel, 1.0f - halfTexel);
}

SHARED_END
#endif
