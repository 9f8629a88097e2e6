// The byte-level pieces of a ray record (ray_record.h's layout), shared by the one-ray encoder
// (ray_record.cpp) and the block encoder (ray_record_wide.cpp). Internal to host/pipeline/.
#pragma once

#include "shared/types.h"

#include <cstdint>
#include <cstring>

namespace spw::record_bytes {

inline void put24(std::uint8_t* p, uint v) {
    p[0] = std::uint8_t(v);
    p[1] = std::uint8_t(v >> 8);
    p[2] = std::uint8_t(v >> 16);
}
inline uint get24(const std::uint8_t* p) {
    return uint(p[0]) | uint(p[1]) << 8 | uint(p[2]) << 16;
}
// The float whose top half is h (a bfloat16 widened).
inline float fromBfloat16(std::uint16_t h) {
    std::uint32_t bits = std::uint32_t(h) << 16;
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}
template <class T> void put(std::uint8_t*& p, T v) {
    std::memcpy(p, &v, sizeof(T));
    p += sizeof(T);
}
template <class T> T get(const std::uint8_t*& p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    p += sizeof(T);
    return v;
}

} // namespace spw::record_bytes
