// runTwin (twins.h): each twin of simd_math-inl.h and simd_bsdf-inl.h on rows of lanes, once per
// instruction set. The rows each twin reads and writes are listed beside it, in its scalar
// function's parameter order.
#include "host/simd/twins.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/simd/twins.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_bsdf-inl.h" // and simd_math-inl.h

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {
namespace {

using simd::Twin;
using simd::TwinLanes;
using simd::TwinResults;

V3 load3(const TwinLanes& in, int row, size_t i) {
    return {load(in.f[row], i), load(in.f[row + 1], i), load(in.f[row + 2], i)};
}
void store3(V3 v, TwinResults& out, int row, size_t i) {
    store(v.x, out.f[row], i);
    store(v.y, out.f[row + 1], i);
    store(v.z, out.f[row + 2], i);
}
U4 loadU4(const TwinLanes& in, int row, size_t i) {
    return {loadU(in.u[row], i), loadU(in.u[row + 1], i), loadU(in.u[row + 2], i),
            loadU(in.u[row + 3], i)};
}
void storeU(VU v, TwinResults& out, int row, size_t i) {
    hn::Store(v, DU(), out.u[row].v + i);
}
void storeU4(U4 v, TwinResults& out, size_t i) {
    storeU(v.x, out, 0, i);
    storeU(v.y, out, 1, i);
    storeU(v.z, out, 2, i);
    storeU(v.w, out, 3, i);
}

// A BSDF sample twin's results: ok u0, specular u1, wi f0-2, weight f3-5, pdf f6, zero where
// the sample failed (the scalar function leaves them unwritten).
void storeSample(const BsdfSample& s, TwinResults& out, size_t i) {
    const V zero = hn::Zero(D());
    store(s.ok, out.u[0], i);
    store(hn::And(s.ok, s.specular), out.u[1], i);
    store3(select(s.ok, s.wi, V3{zero, zero, zero}), out, 0, i);
    store3(select(s.ok, s.weight, V3{zero, zero, zero}), out, 3, i);
    store(hn::IfThenElseZero(s.ok, s.pdf), out.f[6], i);
}
// dot(ng, wo) and the shading frame, from ns, ng and wo in rows nsRow, ngRow and woRow.
struct FrameArgs {
    V3 ng, wo;
    V ngDotWo;
    Frame frame;
};
FrameArgs frameArgs(const TwinLanes& in, int ngRow, int nsRow, int woRow, size_t i) {
    FrameArgs a;
    a.ng = load3(in, ngRow, i);
    a.wo = load3(in, woRow, i);
    a.ngDotWo = dot(a.ng, a.wo);
    a.frame = shadingFrame(facingShadingNormal(load3(in, nsRow, i), a.ng, a.wo, a.ngDotWo));
    return a;
}

// The random-number twins (shared/rng.h) on the vector of lanes starting at i.
void runRandomTwin(Twin twin, const TwinLanes& in, size_t i, TwinResults& out) {
    switch (twin) {
    case Twin::pcg4d: // v u0-3 -> u0-3
        return storeU4(pcg4d(loadU4(in, 0, i)), out, i);
    case Twin::laineKarrasPermutation: // x u0, seed u1 -> u0
        return storeU(laineKarrasPermutation(loadU(in.u[0], i), loadU(in.u[1], i)), out, 0, i);
    case Twin::scrambledSobol4: // sampleIndex u0, key u1-4 -> u0-3
        return storeU4(scrambledSobol4(loadU(in.u[0], i), loadU4(in, 1, i)), out, i);
    case Twin::uintToUnit: // x u0 -> f0
        return store(uintToUnit(loadU(in.u[0], i)), out.f[0], i);
    case Twin::rand4: { // pixel u0, sampleIndex u1, bounce u2; sampling, seed, group uniform
        const U4 r = rand4(in.uniform[0], in.uniform[1], loadU(in.u[0], i), loadU(in.u[1], i),
                           loadU(in.u[2], i), in.uniform[2]);
        store(uintToUnit(r.x), out.f[0], i);
        store(uintToUnit(r.y), out.f[1], i);
        store(uintToUnit(r.z), out.f[2], i);
        return store(uintToUnit(r.w), out.f[3], i);
    }
    default:
        return;
    }
}

// The BSDF twins (shared/ggx.h, conductor.h, dielectric.h, metallic_roughness.h) on the vector of
// lanes starting at i; the others to runRandomTwin.
void runBsdfTwin(Twin twin, const TwinLanes& in, size_t i, TwinResults& out) {
    auto f = [&](int row) { return load(in.f[row], i); };
    switch (twin) {
    case Twin::ggxD: // h f0-2, alpha f3 -> f0
        return store(ggxD(load3(in, 0, i), f(3)), out.f[0], i);
    case Twin::ggxA: // w f0-2, alpha f3 -> f0
        return store(ggxA(load3(in, 0, i), f(3)), out.f[0], i);
    case Twin::ggxG2Denominator: // wo f0-2, wi f3-5, alpha f6 -> f0
        return store(ggxG2Denominator(load3(in, 0, i), load3(in, 3, i), f(6)), out.f[0], i);
    case Twin::ggxSampleVisibleNormal: // wo f0-2, alpha f3, u f4-5 -> f0-2
        return store3(ggxSampleVisibleNormal(load3(in, 0, i), f(3), f(4), f(5)), out, 0, i);
    case Twin::schlickFresnel: // f0 f0-2, cosTheta f3 -> f0-2
        return store3(schlickFresnel(load3(in, 0, i), f(3)), out, 0, i);
    case Twin::conductorEval: { // f0 f0-2, alpha f3, ng f4-6, ns f7-9, wo f10-12, wi f13-15
        const FrameArgs a = frameArgs(in, 4, 7, 10, i);
        V pdf;
        store3(conductorEval(load3(in, 0, i), f(3), a.ng, a.ngDotWo, a.frame, a.wo,
                             load3(in, 13, i), pdf),
               out, 0, i); // -> f0-2, pdf f3
        return store(pdf, out.f[3], i);
    }
    case Twin::conductorSample: { // f0 f0-2, alpha f3, ng f4-6, ns f7-9, wo f10-12, u f13-14
        const FrameArgs a = frameArgs(in, 4, 7, 10, i);
        return storeSample(
            conductorSample(load3(in, 0, i), f(3), a.ng, a.ngDotWo, a.frame, a.wo, f(13), f(14)),
            out, i);
    }
    case Twin::fresnelDielectric: { // cosI f0, eta f1 -> f0, cosT f1
        V cosT;
        store(fresnelDielectric(f(0), f(1), cosT), out.f[0], i);
        return store(cosT, out.f[1], i);
    }
    case Twin::dielectricEval: { // ior f0, alpha f1, ng f2-4, ns f5-7, wo f8-10, wi f11-13
        const FrameArgs a = frameArgs(in, 2, 5, 8, i);
        V pdf;
        store3(dielectricEval(f(0), f(1), a.ng, a.ngDotWo, a.frame, a.wo, load3(in, 11, i), pdf),
               out, 0, i); // -> f0-2, pdf f3
        return store(pdf, out.f[3], i);
    }
    case Twin::dielectricSample: { // ior f0, alpha f1, ng f2-4, ns f5-7, wo f8-10, u f11-13
        const FrameArgs a = frameArgs(in, 2, 5, 8, i);
        return storeSample(
            dielectricSample(f(0), f(1), a.ng, a.ngDotWo, a.frame, a.wo, f(11), f(12), f(13)), out,
            i);
    }
    case Twin::gltfFresnel: // f0 f0-2, f90 f3, cosTheta f4 -> f0-2
        return store3(gltfFresnel(load3(in, 0, i), f(3), f(4)), out, 0, i);
    case Twin::gltfSpecularProbability: // f0 f0-2, cDiff f3-5, cosO f6, f90 f7, alpha f8 -> f0
        return store(gltfSpecularProbability(load3(in, 0, i), f(7), load3(in, 3, i), f(6), f(8)),
                     out.f[0], i);
    case Twin::gltfEval: { // colour f0-2, metallic f3, alpha f4, ng f5-7, ns f8-10, wo f11-13,
                           // wi f14-16, f0d f17-19, f90d f20 -> f0-2, pdf f3
        const FrameArgs a = frameArgs(in, 5, 8, 11, i);
        V pdf;
        store3(gltfEval(load3(in, 0, i), f(3), f(4), load3(in, 17, i), f(20), a.ng, a.ngDotWo,
                        a.frame, a.wo, load3(in, 14, i), pdf),
               out, 0, i);
        return store(pdf, out.f[3], i);
    }
    case Twin::gltfSample: { // colour f0-2, metallic f3, alpha f4, ng f5-7, ns f8-10, wo f11-13,
                             // u f14-16, f0d f17-19, f90d f20
        const FrameArgs a = frameArgs(in, 5, 8, 11, i);
        return storeSample(gltfSample(load3(in, 0, i), f(3), f(4), load3(in, 17, i), f(20), a.ng,
                                      a.ngDotWo, a.frame, a.wo, f(14), f(15), f(16)),
                           out, i);
    }
    default:
        return runRandomTwin(twin, in, i, out);
    }
}

// The twin on the vector of lanes starting at i.
void runVector(Twin twin, const TwinLanes& in, size_t i, TwinResults& out) {
    auto f = [&](int row) { return load(in.f[row], i); };
    switch (twin) {
    case Twin::maxComponent: // v f0-2 -> f0
        return store(maxComponent(load3(in, 0, i)), out.f[0], i);
    case Twin::quantizePdf: // pdf f0 -> f0
        return store(quantizePdf(f(0)), out.f[0], i);
    case Twin::powerHeuristic: // pdfThis f0, pdfOther f1 -> f0
        return store(powerHeuristic(f(0), f(1)), out.f[0], i);
    case Twin::facingShadingNormal: { // ns f0-2, ng f3-5, wo f6-8 -> f0-2
        const V3 ng = load3(in, 3, i), wo = load3(in, 6, i);
        return store3(facingShadingNormal(load3(in, 0, i), ng, wo, dot(ng, wo)), out, 0, i);
    }
    case Twin::sinQuarterPi: // x f0 -> f0
        return store(sinQuarterPi(f(0)), out.f[0], i);
    case Twin::cosQuarterPi: // x f0 -> f0
        return store(cosQuarterPi(f(0)), out.f[0], i);
    case Twin::sampleCosineHemisphere: // u f0-1 -> f0-2
        return store3(sampleCosineHemisphere(f(0), f(1)), out, 0, i);
    case Twin::toWorld: // local f0-2, n f3-5 -> f0-2
        return store3(toWorld(load3(in, 0, i), load3(in, 3, i)), out, 0, i);
    case Twin::surfaceOffset: // p f0-2, v0 f3-5, v1 f6-8, v2 f9-11, n f12-14 -> f0
        return store(surfaceOffset(load3(in, 0, i), load3(in, 3, i), load3(in, 6, i),
                                   load3(in, 9, i), load3(in, 12, i)),
                     out.f[0], i);
    case Twin::offsetOrigin: // p f0-2, ng f3-5, offset f6, dir f7-9 -> f0-2
        return store3(offsetOrigin(load3(in, 0, i), load3(in, 3, i), f(6), load3(in, 7, i)), out, 0,
                      i);
    case Twin::shadowRayTmax: // dist f0, offsetP f1, offsetQ f2, cosQ f3 -> f0
        return store(shadowRayTmax(f(0), f(1), f(2), f(3)), out.f[0], i);
    case Twin::shadowLift: // ng f0-2, lift f3, dir f4-6, tmax f7 -> f0
        return store(shadowLift(load3(in, 0, i), f(3), load3(in, 4, i), f(7)), out.f[0], i);
    case Twin::emitterPoint: // p0 f0-2, e1 f3-5, e2 f6-8, u f9-10 -> f0-2
        return store3(emitterPoint(load3(in, 0, i), load3(in, 3, i), load3(in, 6, i), f(9), f(10)),
                      out, 0, i);
    case Twin::emitterCosine: // normal f0-2, twoSided u0 (mask), towardReceiver f3-5 -> f0
        return store(emitterCosine(load3(in, 0, i), loadMask(in.u[0], i), load3(in, 3, i)),
                     out.f[0], i);
    case Twin::emitterSolidAnglePdf: // pickPdf f0, area f1, dist f2, cosLight f3 -> f0
        return store(emitterSolidAnglePdf(f(0), f(1), f(2), f(3)), out.f[0], i);
    case Twin::lambertEval: { // albedo f0-2, ng f3-5, ns f6-8, wo f9-11, wi f12-14 -> f0-2, pdf f3
        const V3 ng = load3(in, 3, i);
        const V3 wo = load3(in, 9, i);
        const V ngDotWo = dot(ng, wo);
        const V3 n = facingShadingNormal(load3(in, 6, i), ng, wo, ngDotWo);
        V pdf;
        store3(lambertEval(load3(in, 0, i), ng, ngDotWo, n, load3(in, 12, i), pdf), out, 0, i);
        return store(pdf, out.f[3], i);
    }
    default:
        return runBsdfTwin(twin, in, i, out);
    }
}

} // namespace

void RunTwin(Twin twin, const TwinLanes& in, size_t count, TwinResults& out) {
    for (size_t i = 0; i < count; i += hn::Lanes(D()))
        runVector(twin, in, i, out);
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw::simd {
HWY_EXPORT(RunTwin);

void runTwin(Twin twin, const TwinLanes& in, size_t count, TwinResults& out) {
    HWY_DYNAMIC_DISPATCH(RunTwin)(twin, in, count, out);
}

} // namespace spw::simd
#endif
