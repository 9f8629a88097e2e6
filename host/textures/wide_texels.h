// Bilinear filtering of 8-bit texels SIMD-wide, for a run of lookups in one tile (Google
// Highway, dynamic dispatch, as the shading kernels). The texture resolver (textures.cpp) holds
// the tile; this file only reads it. Each lane is the resolver's scalar bilinear filter to the
// bit: the same operations in the same order, each rounded once (no fused multiply-add), and
// the same decoding table (TextureLookup.WideFilteringIsTheScalarLookupBitForBit).
#pragma once

#include "host/simd/lanes.h"

#include <cstddef>

namespace spw {

// One tile of 8-bit texels: [x0, x1) x [y0, y1) of a level, `bytes` of them at `pixels`, a
// texel `pixelBytes` (its channels) apart and a row `rowBytes` apart. A texel's first
// min(channels, 3) bytes are its channels (one channel is grey: all three), each decoded
// through `decode` (256 linear values: the sRGB curve or i / 255).
struct TexelTile {
    const unsigned char* pixels = nullptr;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int pixelBytes = 0, rowBytes = 0, bytes = 0, channels = 0;
    const float* decode = nullptr;
};

// The data window of the level the tile belongs to, which the lookups repeat over.
struct TexelLevel {
    int x = 0, y = 0, width = 1, height = 1;
};

// A block of lookups, a row of lanes per value (host/simd/lanes.h).
struct TexelLanes {
    simd::Floats s, t;    // image-space coordinates (t grows downwards)
    simd::Floats r, g, b; // the filtered value
    simd::Uints done;     // all ones: r, g, b are the lane's value
};

// Lanes [0, count) (count a multiple of simd::kMaxLanes, at most simd::kBlock) of `lanes`: where
// all four texels a lane's bilinear filter reads lie in `tile`, r, g, b are the filtered value
// and `done` all ones; elsewhere `done` is 0 and r, g, b are not to be read. Needs
// tile.bytes >= 4 (it reads texels as 32-bit words).
void bilinearInTile(const TexelTile& tile, const TexelLevel& level, size_t count,
                    TexelLanes& lanes);

// A Layered texture's values for a run of lookups, SIMD-wide: out[i] = mask[i] upper[i] +
// (1 - mask[i]) lower[i] for i in [0, count), each operation rounded once, as the scalar blend
// of one channel (a run's vec3 values are rows of 3 n floats). `out` may be any of the inputs.
void blendLayers(size_t count, const float* mask, const float* upper, const float* lower,
                 float* out);

} // namespace spw
