#include "host/pipeline/ray_record.h"

#include "host/pipeline/record_bytes.h"

#include "host/scene/scene.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace spw {

static_assert(kMaxCompactBounce >= uint(kMaxDepth),
              "the loader accepts depths the compact ray cannot hold");

namespace {
using namespace record_bytes;

constexpr double kOctScale = double((1u << 24) - 1);

// Branch-free `c ? a : b` and `a * (s >= 0 ? 1 : -1)`, with exactly their results: bounce
// directions make such branches coin flips, which cost more than the arithmetic.
double pick(bool c, double a, double b) {
    std::uint64_t x, y;
    std::memcpy(&x, &a, 8);
    std::memcpy(&y, &b, 8);
    const std::uint64_t mask = std::uint64_t(0) - std::uint64_t(c);
    const std::uint64_t r = (x & mask) | (y & ~mask);
    double out;
    std::memcpy(&out, &r, 8);
    return out;
}
double signOf(double s, double a) {
    std::uint64_t x;
    std::memcpy(&x, &a, 8);
    x ^= std::uint64_t(!(s >= 0)) << 63;
    double out;
    std::memcpy(&out, &x, 8);
    return out;
}

void octEncode(vec3 d, uint& u, uint& v) {
    const glm::dvec2 p = octahedralMap(d);
    u = uint((p.x * 0.5 + 0.5) * kOctScale + 0.5); // round to nearest (the value is >= 0)
    v = uint((p.y * 0.5 + 0.5) * kOctScale + 0.5);
}

vec3 octDecode(uint u, uint v) {
    // Multiplications by reciprocals rather than divisions: each adds at most an ulp of a
    // double, 2^-29 of the float the direction is rounded to.
    constexpr double kToUnit = 2.0 / kOctScale;
    glm::dvec2 p(double(u) * kToUnit - 1.0, double(v) * kToUnit - 1.0);
    const double z = 1.0 - std::fabs(p.x) - std::fabs(p.y);
    const glm::dvec2 f = octahedralFold(p);
    p = glm::dvec2(pick(z < 0, f.x, p.x), pick(z < 0, f.y, p.y));
    const double inv = 1.0 / std::sqrt(p.x * p.x + p.y * p.y + z * z);
    return vec3(float(p.x * inv), float(p.y * inv), float(z * inv));
}

// bfloat16 with stochastic rounding: round the magnitude up with probability (dropped bits / 2^16).
std::uint16_t toBfloat16(float f, uint random) {
    std::uint32_t bits;
    std::memcpy(&bits, &f, 4);
    std::uint32_t hi = bits >> 16, lo = bits & 0xFFFFu;
    // Without a branch (the comparison is a coin flip); never rounds into Inf/NaN.
    hi += std::uint32_t((random & 0xFFFFu) < lo) & std::uint32_t((hi & 0x7F80u) != 0x7F80u);
    return std::uint16_t(hi);
}

} // namespace

glm::dvec2 octahedralFold(glm::dvec2 p) {
    return glm::dvec2(signOf(p.x, 1.0 - std::fabs(p.y)), signOf(p.y, 1.0 - std::fabs(p.x)));
}

glm::dvec2 octahedralMap(vec3 d) {
    const double x = d.x, y = d.y, z = d.z;
    const double inv = 1.0 / (std::fabs(x) + std::fabs(y) + std::fabs(z)); // one division
    const glm::dvec2 p(x * inv, y * inv);
    const glm::dvec2 f = octahedralFold(p);
    return glm::dvec2(pick(z < 0, f.x, p.x), pick(z < 0, f.y, p.y));
}

void encodeRay(vec3 origin, vec3 dir, const PathState& path, RayFormat format, uvec4 rounding,
               std::uint8_t* out) {
    std::uint8_t* p = out;
    for (int i = 0; i < 3; ++i)
        put<float>(p, origin[i]);
    put<std::uint32_t>(p, path.pathId);
    if (format == RayFormat::Full) {
        for (int i = 0; i < 3; ++i)
            put<float>(p, dir[i]);
        for (int i = 0; i < 3; ++i)
            put<float>(p, path.beta[i]);
        put<float>(p, path.prevPdf);
        put<std::uint32_t>(p, path.bounce | path.flags << 16);
        put<std::uint16_t>(p, std::uint16_t(path.cone));
        return;
    }
    uint u, v;
    octEncode(dir, u, v);
    put24(p, u);
    put24(p + 3, v);
    p += 6;
    // One random number for the three channels: rounding stays monotone, so the largest channel
    // (what Russian roulette reads) is still unbiased after rounding (ray_record.h).
    put<std::uint16_t>(p, toBfloat16(path.beta.x, rounding.x));
    put<std::uint16_t>(p, toBfloat16(path.beta.y, rounding.x));
    put<std::uint16_t>(p, toBfloat16(path.beta.z, rounding.x));
    put<std::uint16_t>(p, std::uint16_t(floatBitsToUint(path.prevPdf) >> 16));
    put<std::uint16_t>(p, compactBounce(path));
    put<std::uint16_t>(p, std::uint16_t(path.cone));
}

void decodeRay(const std::uint8_t* in, RayFormat format, RayState& r) {
    const std::uint8_t* p = in;
    for (int i = 0; i < 3; ++i)
        r.origin[i] = get<float>(p);
    r.path.pathId = get<std::uint32_t>(p);
    if (format == RayFormat::Full) {
        for (int i = 0; i < 3; ++i)
            r.dir[i] = get<float>(p);
        for (int i = 0; i < 3; ++i)
            r.path.beta[i] = get<float>(p);
        r.path.prevPdf = get<float>(p);
        std::uint32_t bf = get<std::uint32_t>(p);
        r.path.bounce = bf & 0xFFFFu;
        r.path.flags = bf >> 16;
        r.path.cone = get<std::uint16_t>(p);
        return;
    }
    r.dir = octDecode(get24(p), get24(p + 3));
    p += 6;
    r.path.beta.x = fromBfloat16(get<std::uint16_t>(p));
    r.path.beta.y = fromBfloat16(get<std::uint16_t>(p));
    r.path.beta.z = fromBfloat16(get<std::uint16_t>(p));
    r.path.prevPdf = fromBfloat16(get<std::uint16_t>(p));
    std::uint16_t bf = get<std::uint16_t>(p);
    r.path.bounce = bf & 0x7FFFu;
    r.path.flags = (bf & 0x8000u) ? kPathSpecular : 0u;
    r.path.cone = get<std::uint16_t>(p);
}

} // namespace spw
