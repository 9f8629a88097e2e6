// The SIMD shading kernels (simd_shading.h). Highway compiles the part between
// HWY_BEFORE_NAMESPACE and HWY_AFTER_NAMESPACE once per instruction set (this file includes
// itself through foreach_target.h) and picks the best the processor has at the first call.
//
// Each kernel is shadeSurface() (shared/path.h) for one surface model (shared/lambert.h,
// conductor.h, dielectric.h, metallic_roughness.h): shadeLanes() is its control flow, and a
// small struct per model supplies bsdfEval, bsdfSample and bsdfIsDelta as the SIMD twins of the
// model's shared functions (host/simd/simd_math-inl.h and simd_bsdf-inl.h, each checked against its
// scalar function lane by lane).
#include "host/cpu/simd_shading.h"
#include "host/cpu/wide_models.h"

#include "host/cpu/simd_light_pick.h"

#include "host/simd/lanes.h"
#include "shared/path.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

#ifndef SPILLWAY_SIMD_SHADING_LANES
#define SPILLWAY_SIMD_SHADING_LANES
namespace spw::simd_shading {

using simd::Floats;
using simd::kBlock;
using simd::Uints;
using simd::Vec3s;

// Every struct of lanes below is rows of kBlock 4-byte values and nothing else, so padding a
// block copies rows (padLanes).

// The random numbers of up to kBlock hits: what they are a function of, and what
// MakeRandomNumbers makes of it.
struct RandomLanes {
    Uints pixel, sampleIndex, bounce;
    Floats uLightX, uLightY, uLightZ, uLightW; // rand4(kDimLight)
    Floats uBsdfX, uBsdfY, uBsdfZ;             // rand4(kDimBsdf).xyz
};

// A kernel's inputs for up to kBlock hits of one surface model.
struct SurfaceLanes {
    Vec3s p, ng, ns, albedo, wo, beta; // the hit, -rayDir, the path's throughput
    Floats offset, lift;
    Floats alpha, ior, metallic; // the shader's GGX width, index of refraction and metalness
    Vec3s f0d;                   // MetallicRoughness: the dielectric part's F0 colour
    Floats f90d;    // and its F90 (shared/metallic_roughness.h); zeros for other models
    Uints live;     // bounce < max depth: the path goes on from here
    Uints roulette; // bounce >= min depth
    RandomLanes random;
    Vec3s e0, e1, e2, eNormal, eRadiance; // the picked emitter (a triangle)
    Floats ePickPdf, eArea;
    Uints eTwoSided;
    // Where the picked emitter is not a triangle without an emission map (a punctual light,
    // the environment, a mapped triangle), its light sample, made one lane at a time by
    // sampleEmitter: eSampled set, the direction, the shadow ray's length, the pdf, whether it is
    // a delta light, and in eRadiance the radiance it brings.
    Uints eSampled, eDelta;
    Vec3s sWi;
    Floats sTmax, sPdf;
};
static_assert(sizeof(SurfaceLanes) % sizeof(Floats) == 0, "rows only");
static_assert(sizeof(RandomLanes) % sizeof(Floats) == 0, "rows only");

// What a kernel writes; shadeHits() puts it into the ShadeResults.
struct SurfaceResults {
    Uints shadow, next, specular; // kShadeShadow, kShadeContinue, kPathSpecular
    Vec3s shadowOrigin, shadowDir, shadowContribution, nextOrigin, nextDir, nextBeta;
    Floats shadowTmax, nextPdf;
};

} // namespace spw::simd_shading
#endif

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/cpu/simd_shading.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_bsdf-inl.h" // and simd_math-inl.h
#include "wide_model_lanes.h"        // each SIMD-wide model's <Name>LanesModel (wide_models.h)

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

// The lanes' rand4(kDimLight) and rand4(kDimBsdf).xyz, for lanes [0, count).
void MakeRandomNumbers(simd_shading::RandomLanes& lanes, size_t count, uint sampling, uint seed) {
    for (size_t i = 0; i < count; i += hn::Lanes(D())) {
        const VU pixel = loadU(lanes.pixel, i), sampleIndex = loadU(lanes.sampleIndex, i);
        const VU bounce = loadU(lanes.bounce, i);
        const U4 light = rand4(sampling, seed, pixel, sampleIndex, bounce, kDimLight);
        store(uintToUnit(light.x), lanes.uLightX, i);
        store(uintToUnit(light.y), lanes.uLightY, i);
        store(uintToUnit(light.z), lanes.uLightZ, i);
        store(uintToUnit(light.w), lanes.uLightW, i);
        const U4 bsdf = rand4(sampling, seed, pixel, sampleIndex, bounce, kDimBsdf);
        store(uintToUnit(bsdf.x), lanes.uBsdfX, i);
        store(uintToUnit(bsdf.y), lanes.uBsdfY, i);
        store(uintToUnit(bsdf.z), lanes.uBsdfZ, i);
    }
}

// Twin of terminatorEval (shared/path.h) for the lanes `candidates` selects (those whose BSDF
// gave nothing toward wi): fcos and toward replaced where it applies.
template <class Model>
void terminatorLanes(const HitVector& h, V3 wi, V lift, M candidates, V3& fcos, V3& toward) {
    const D d;
    const V zero = hn::Zero(d);
    M terminator = hn::And(candidates, hn::Gt(hn::Mul(h.ngDotWo, lift), zero));
    terminator = hn::AndNot(hn::Gt(hn::Mul(h.ngDotWo, dot(h.ng, wi)), zero), terminator);
    terminator =
        hn::And(terminator, hn::And(hn::Gt(dot(h.ns, h.wo), zero), hn::Gt(dot(h.ns, wi), zero)));
    if (hn::AllFalse(d, terminator)) return;
    HitVector smooth = h; // the interpolated normal as the geometric one
    smooth.ng = h.ns;
    smooth.ngDotWo = dot(h.ns, h.wo);
    smooth.n = facingShadingNormal(h.ns, h.ns, h.wo, smooth.ngDotWo);
    const Model smoothModel(smooth);
    V unusedPdf;
    const V3 smoothFcos = smoothModel.eval(smooth, wi, unusedPdf);
    fcos = select(terminator, smoothFcos, fcos);
    toward = select(hn::And(terminator, hn::Gt(maxComponent(smoothFcos), zero)), h.wo, wi);
}

// Step 2 of shadeSurface, next-event estimation toward a point of the picked triangle
// (sampleEmitter), for the lanes `shadowing` selects; the mask of those that send a shadow ray.
template <class Model>
M shadowLanes(const simd_shading::SurfaceLanes& in, size_t i, const HitVector& h,
              const Model& model, V3 p, V3 beta, V offset, M shadowing, bool mis,
              simd_shading::SurfaceResults& out) {
    const D d;
    const V zero = hn::Zero(d);
    const V3 e0 = load(in.e0, i), e1 = load(in.e1, i), e2 = load(in.e2, i);
    const V3 eNormal = load(in.eNormal, i);
    const V3 q = emitterPoint(e0, e1, e2, load(in.random.uLightY, i), load(in.random.uLightZ, i));
    const V3 dq = sub(q, p);
    const V dist = hn::Sqrt(dot(dq, dq));
    const V3 toQ = div(dq, dist);
    const V cosLight = emitterCosine(eNormal, loadMask(in.eTwoSided, i), neg(toQ));
    const V trianglePdf =
        emitterSolidAnglePdf(load(in.ePickPdf, i), load(in.eArea, i), dist, cosLight);
    const V offsetQ = surfaceOffset(q, e0, add(e0, e1), add(e0, e2), eNormal);
    // The lanes whose sample sampleEmitter made take it instead of the triangle's.
    const M sampled = loadMask(in.eSampled, i);
    const V3 wi = select(sampled, load(in.sWi, i), toQ);
    const V pdf = hn::IfThenElse(sampled, load(in.sPdf, i), trianglePdf);
    const V tmax =
        hn::IfThenElse(sampled, load(in.sTmax, i), shadowRayTmax(dist, offset, offsetQ, cosLight));

    shadowing = hn::And(shadowing, hn::And(hn::Or(sampled, hn::Gt(dist, zero)), hn::Gt(pdf, zero)));

    V bsdfPdf;
    V3 fcos = model.eval(h, wi, bsdfPdf);
    // Where the BSDF gives nothing: terminatorEval, and a pdf of 0.
    const M none = hn::Not(hn::Gt(maxComponent(fcos), zero));
    bsdfPdf = hn::IfThenZeroElse(none, bsdfPdf);
    const V lift = load(in.lift, i);
    V3 toward = wi;
    terminatorLanes<Model>(h, wi, lift, hn::And(shadowing, none), fcos, toward);
    shadowing = hn::And(shadowing, hn::Gt(maxComponent(fcos), zero));

    // A delta light (a point, a direction): BSDF sampling cannot find it, no MIS.
    const V w = hn::IfThenElse(loadMask(in.eDelta, i), hn::Set(d, 1.0f),
                               mis ? powerHeuristic(pdf, quantizePdf(bsdfPdf)) : hn::Set(d, 1.0f));
    const V3 radiance = load(in.eRadiance, i);
    const V lifted = shadowLift(h.ng, lift, toward, tmax);
    const V liftedTmax = hn::Sub(tmax, hn::Mul(hn::Set(d, 2.0f), lifted));
    store(shadowing, offsetOrigin(p, h.ng, hn::Add(offset, lifted), toward), out.shadowOrigin, i);
    store(shadowing, wi, out.shadowDir, i);
    store(hn::IfThenElseZero(shadowing, liftedTmax), out.shadowTmax, i);
    store(shadowing, mul(mul(mul(beta, fcos), radiance), hn::Div(w, pdf)), out.shadowContribution,
          i);
    return hn::And(shadowing, hn::Gt(liftedTmax, zero));
}

// Steps 2 and 3 of shadeSurface for lanes [0, count) of one model's hits, count a multiple of
// the vector width.
template <class Model>
void shadeLanes(const simd_shading::SurfaceLanes& in, size_t count, bool nee, bool mis,
                float threshold, simd_shading::SurfaceResults& out) {
    const D d;
    const V zero = hn::Zero(d);
    const V one = hn::Set(d, 1.0f);
    for (size_t i = 0; i < count; i += hn::Lanes(d)) {
        HitVector h;
        const V3 p = load(in.p, i), ns = load(in.ns, i), beta = load(in.beta, i);
        h.ng = load(in.ng, i), h.albedo = load(in.albedo, i), h.wo = load(in.wo, i);
        h.alpha = load(in.alpha, i), h.ior = load(in.ior, i), h.metallic = load(in.metallic, i);
        h.f0d = load(in.f0d, i), h.f90d = load(in.f90d, i);
        h.ngDotWo = dot(h.ng, h.wo);
        h.ns = ns;
        h.n = facingShadingNormal(ns, h.ng, h.wo, h.ngDotWo);
        const Model model(h);
        const V offset = load(in.offset, i);
        const M live = loadMask(in.live, i);

        // 2. Next-event estimation, where the BSDF is not delta lobes alone.
        M shadowing = hn::AndNot(model.delta(h), live);
        if (!nee) shadowing = hn::FirstN(d, 0);
        if (!hn::AllFalse(d, shadowing)) {
            shadowing = shadowLanes(in, i, h, model, p, beta, offset, shadowing, mis, out);
        } else {
            const V3 none = {zero, zero, zero};
            store(shadowing, none, out.shadowOrigin, i);
            store(shadowing, none, out.shadowDir, i);
            store(zero, out.shadowTmax, i);
            store(shadowing, none, out.shadowContribution, i);
        }
        store(shadowing, out.shadow, i);

        // 3. Continuation: the BSDF's sample, then Russian roulette.
        const BsdfSample s = model.sample(h, load(in.random.uBsdfX, i), load(in.random.uBsdfY, i),
                                          load(in.random.uBsdfZ, i));
        M next = hn::And(live, s.ok);
        V3 nextBeta = mul(beta, s.weight);
        const V q = gmin(one, hn::Div(maxComponent(nextBeta), hn::Set(d, threshold)));
        const M roulette = loadMask(in.roulette, i);
        next = hn::And(next, hn::Or(hn::Not(roulette), hn::Lt(load(in.random.uLightW, i), q)));
        nextBeta = select(roulette, div(nextBeta, q), nextBeta);
        next = hn::And(next, hn::Gt(maxComponent(nextBeta), zero));
        store(next, out.next, i);
        store(hn::And(next, s.specular), out.specular, i);
        store(next, offsetOrigin(p, h.ng, offset, s.wi), out.nextOrigin, i);
        store(next, s.wi, out.nextDir, i);
        store(next, nextBeta, out.nextBeta, i);
        store(hn::IfThenElseZero(next, quantizePdf(s.pdf)), out.nextPdf, i);
    }
}

// Each SIMD-wide model's kernel: Shade<Name>Lanes, shadeLanes over its <Name>LanesModel.
#define SPW_SHADE_LANES(Name, stem)                                                                \
    void Shade##Name##Lanes(const simd_shading::SurfaceLanes& in, size_t count, bool nee,          \
                            bool mis, float threshold, simd_shading::SurfaceResults& out) {        \
        shadeLanes<Name##LanesModel>(in, count, nee, mis, threshold, out);                         \
    }
SPW_WIDE_MODELS(SPW_SHADE_LANES)
#undef SPW_SHADE_LANES

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
#define SPW_EXPORT_LANES(Name, stem) HWY_EXPORT(Shade##Name##Lanes);
SPW_WIDE_MODELS(SPW_EXPORT_LANES)
#undef SPW_EXPORT_LANES
HWY_EXPORT(MakeRandomNumbers);

using simd::kBlock;
using simd::wholeVectors;
using simd_shading::SurfaceLanes;
using simd_shading::SurfaceResults;

namespace {

void set(simd::Vec3s& a, size_t k, vec3 v) {
    a.x.v[k] = v.x;
    a.y.v[k] = v.y;
    a.z.v[k] = v.z;
}
vec3 get(const simd::Vec3s& a, size_t k) {
    return vec3(a.x.v[k], a.y.v[k], a.z.v[k]);
}
std::uint32_t mask(bool b) {
    return b ? ~0u : 0u;
}

// Lane k of `lanes`: what path st's random numbers at this bounce are a function of.
void setRandomLane(const RenderParams& rp, const PathState& st, simd_shading::RandomLanes& lanes,
                   size_t k) {
    lanes.pixel.v[k] = pathPixel(rp, st.pathId);
    lanes.sampleIndex.v[k] = pathSample(rp, st.pathId);
    lanes.bounce.v[k] = st.bounce;
}

// Lane k from hit `in`: what the kernel reads, and (scalar) the emission into `out`.
void fillLane(const SceneView& scene, const RenderParams& rp, const ShadeInput& in,
              SurfaceLanes& lanes, size_t k, ShadeResult& out) {
    const SurfaceHit& hit = in.hit;
    const vec3 wo = -in.rayDir;
    const ShaderParams sh = shaderAtHit(scene.shaders[hit.shader], hit);
    const PathState st = throughMedium(sh, hit, wo, in.path);
    out.flags = 0u;
    out.emitted = vec3(0.0f);
    addEmission(scene, rp, hit, wo, st, out);
    set(lanes.p, k, hit.p);
    set(lanes.ng, k, hit.ng);
    set(lanes.ns, k, hit.ns);
    set(lanes.albedo, k, hit.albedo);
    set(lanes.wo, k, wo);
    set(lanes.beta, k, st.beta);
    lanes.offset.v[k] = hit.offset;
    lanes.lift.v[k] = hit.lift;
    lanes.alpha.v[k] = sh.alpha;
    lanes.ior.v[k] = sh.ior;
    const bool gltf = sh.model == kModelMetallicRoughness;
    set(lanes.f0d, k, gltf ? gltfDielectricF0Colour(sh) : vec3(0.0f));
    lanes.f90d.v[k] = gltf ? gltfDielectricF90(sh) : 0.0f;
    lanes.metallic.v[k] = sh.metallic;
    const bool live = st.bounce < rp.maxDepth;
    lanes.live.v[k] = mask(live);
    lanes.roulette.v[k] = mask(st.bounce >= rp.minDepth);
    setRandomLane(rp, st, lanes.random, k);
}

// Lane k's emitter, `picked` with probability pickPdf (zeros where the path ends here or nothing
// is sampled, so that the kernel reads defined values); where it is not a triangle without an
// emission map, its light sample from `hit`, made here.
void pickLaneEmitter(const SceneView& scene, const RenderParams& rp, uint picked, float pickPdf,
                     const SurfaceHit& hit, SurfaceLanes& lanes, size_t k) {
    static const Emitter kNone{};
    const Emitter& e = picked != kNoEmitter ? scene.emitters[picked] : kNone;
    const bool sampled =
        picked != kNoEmitter && (e.type != kEmitterTriangle || e.map != kNoEmissionMap);
    lanes.eSampled.v[k] = mask(sampled);
    lanes.eDelta.v[k] = mask(sampled && emitterIsDelta(e.type));
    if (sampled) {
        Emitter withPdf = e;
        withPdf.pickPdf = pickPdf;
        const LightSample ls = sampleEmitter(
            scene, rp, withPdf, hit, vec2(lanes.random.uLightY.v[k], lanes.random.uLightZ.v[k]));
        set(lanes.sWi, k, ls.wi);
        lanes.sTmax.v[k] = ls.tmax;
        lanes.sPdf.v[k] = ls.pdf;
        set(lanes.e0, k, vec3(0.0f));
        set(lanes.e1, k, vec3(0.0f));
        set(lanes.e2, k, vec3(0.0f));
        set(lanes.eNormal, k, vec3(0.0f, 0.0f, 1.0f));
        set(lanes.eRadiance, k, ls.radiance);
        lanes.ePickPdf.v[k] = 0.0f;
        lanes.eArea.v[k] = 1.0f;
        lanes.eTwoSided.v[k] = 0u;
        return;
    }
    set(lanes.sWi, k, vec3(0.0f, 0.0f, 1.0f));
    lanes.sTmax.v[k] = 0.0f;
    lanes.sPdf.v[k] = 0.0f;
    set(lanes.e0, k, e.p0);
    set(lanes.e1, k, e.e1);
    set(lanes.e2, k, e.e2);
    set(lanes.eNormal, k, e.normal);
    set(lanes.eRadiance, k, e.radiance);
    lanes.ePickPdf.v[k] = pickPdf;
    lanes.eArea.v[k] = e.area;
    lanes.eTwoSided.v[k] = mask(e.twoSided != 0u);
}

// Lanes [count, end) copies of lane 0, so that whole vectors read defined values.
template <class Lanes> void padLanes(Lanes& lanes, size_t count, size_t end) {
    auto* rows = reinterpret_cast<unsigned char*>(&lanes);
    for (size_t row = 0; row < sizeof(Lanes); row += sizeof(simd::Floats))
        for (size_t k = count; k < end; ++k)
            std::memcpy(rows + row + 4 * k, rows + row, 4);
}

// The kernel's results for lane k into `out` (whose emission fillLane wrote).
void takeLane(const ShaderParams& sh, const SurfaceResults& res, size_t k, const ShadeInput& in,
              ShadeResult& out) {
    const PathState st = throughMedium(sh, in.hit, -in.rayDir, in.path); // as fillLane's
    out.shadowOrigin = get(res.shadowOrigin, k);
    out.shadowDir = get(res.shadowDir, k);
    out.shadowTmax = res.shadowTmax.v[k];
    out.shadowContribution = get(res.shadowContribution, k);
    out.nextOrigin = get(res.nextOrigin, k);
    out.nextDir = get(res.nextDir, k);
    out.next = st;
    if (res.shadow.v[k]) out.flags |= kShadeShadow;
    if (!res.next.v[k]) return;
    out.next.beta = get(res.nextBeta, k);
    out.next.prevPdf = res.nextPdf.v[k];
    out.next.bounce = st.bounce + 1u;
    const bool specular = res.specular.v[k] != 0u;
    out.next.flags = specular ? kPathSpecular : 0u;
    out.next.cone = packCone(coneWidthAt(st.cone, in.hit.t),
                             coneSpread(st.cone) + bsdfConeSpread(sh, specular));
    out.flags |= kShadeContinue;
}

} // namespace

namespace {
// Each SIMD-wide model's kernel in the best instruction set the processor has.
#define SPW_DISPATCH_LANES(Name, stem)                                                             \
    void shade##Name##Lanes(const SurfaceLanes& in, size_t count, bool nee, bool mis,              \
                            float threshold, SurfaceResults& out) {                                \
        HWY_DYNAMIC_DISPATCH(Shade##Name##Lanes)(in, count, nee, mis, threshold, out);             \
    }
SPW_WIDE_MODELS(SPW_DISPATCH_LANES)
#undef SPW_DISPATCH_LANES

// Every model's entry, empty but for the SIMD-wide ones'.
constexpr std::array<WideTwin, kModelCount> wideTwins() {
    std::array<WideTwin, kModelCount> twins{};
    for (uint model = 0; model < kModelCount; ++model)
        twins[model] = {model, nullptr};
#define SPW_WIDE_TWIN(Name, stem) twins[kModel##Name].shade = &shade##Name##Lanes;
    SPW_WIDE_MODELS(SPW_WIDE_TWIN)
#undef SPW_WIDE_TWIN
    return twins;
}
} // namespace

const std::array<WideTwin, kModelCount> kWideTwins = wideTwins();

namespace {
// A block of hits per model with a kernel, filled as the hits come: runs of one shader where the
// hits are sorted, interleaved models where they are not.
struct ModelBlock {
    SurfaceLanes lanes;
    std::uint32_t hitOf[kBlock];
    size_t count = 0;
};

// The hits of a block of one model with a kernel, shaded SIMD-wide into out[b.hitOf[k]]; the
// block is emptied. `results` is scratch.
void shadeBlock(const SceneView& view, const RenderParams& rp, bool nee, bool mis, uint model,
                const ShadeInput* in, ModelBlock& b, SurfaceResults& results, ShadeResult* out) {
    const size_t end = wholeVectors(b.count);
    padLanes(b.lanes, b.count, end);
    HWY_DYNAMIC_DISPATCH(MakeRandomNumbers)(b.lanes.random, end, rp.sampling, rp.seed);
    uint picked[kBlock];
    float pickPdf[kBlock];
    pickLights(view, rp, b.lanes.p, b.lanes.random.uLightX, nee ? b.lanes.live : simd::Uints{}, end,
               picked, pickPdf);
    for (size_t k = 0; k < end; ++k) // padding lanes are lane 0's copies
        pickLaneEmitter(view, rp, picked[k], pickPdf[k], in[b.hitOf[k < b.count ? k : 0]].hit,
                        b.lanes, k);
    kWideTwins[model].shade(b.lanes, end, nee, mis, rp.threshold, results);
    for (size_t k = 0; k < b.count; ++k) {
        const ShadeInput& hit = in[b.hitOf[k]];
        takeLane(shaderAtHit(view.shaders[hit.hit.shader], hit.hit), results, k, hit,
                 out[b.hitOf[k]]);
    }
    b.count = 0;
}
} // namespace

void shadeHits(const SceneView& view, const RenderParams& rp, bool simd, const ShadeInput* in,
               size_t n, ShadeResult* out) {
    if (!simd) {
        for (size_t i = 0; i < n; ++i)
            shadeSurface(view, rp, in[i].hit, in[i].rayDir, in[i].path, out[i]);
        return;
    }
    const bool nee = rp.emitterCount > 0u && rp.strategy != kStrategyBsdf;
    const bool mis = rp.strategy == kStrategyMis;
    // The other models' hits that go on: shadeSurface with their random numbers made here.
    simd_shading::RandomLanes others;
    std::uint32_t otherOf[kBlock];
    size_t otherCount = 0;
    auto runOthers = [&] {
        const size_t end = wholeVectors(otherCount);
        padLanes(others, otherCount, end);
        HWY_DYNAMIC_DISPATCH(MakeRandomNumbers)(others, end, rp.sampling, rp.seed);
        for (size_t k = 0; k < otherCount; ++k) {
            const ShadeInput& hit = in[otherOf[k]];
            const vec4 uLight(others.uLightX.v[k], others.uLightY.v[k], others.uLightZ.v[k],
                              others.uLightW.v[k]);
            const vec4 uBsdf(others.uBsdfX.v[k], others.uBsdfY.v[k], others.uBsdfZ.v[k], 0.0f);
            shadeSurfaceWith(view, rp, hit.hit, hit.rayDir, hit.path, uLight, uBsdf,
                             out[otherOf[k]]);
        }
        otherCount = 0;
    };
    ModelBlock blocks[kModelCount];
    SurfaceResults results;
    auto run = [&](uint model) {
        shadeBlock(view, rp, nee, mis, model, in, blocks[model], results, out);
    };
    for (size_t i = 0; i < n; ++i) {
        const ShaderParams& sh = view.shaders[in[i].hit.shader];
        if (!kWideTwins[sh.model].shade) { // shadeSurfaceWith, one hit at a time
            if (!shadeGoesOn(rp, sh, in[i].path)) {
                shadeSurfaceWith(view, rp, in[i].hit, in[i].rayDir, in[i].path, vec4(0.0f),
                                 vec4(0.0f), out[i]);
                continue;
            }
            setRandomLane(rp, in[i].path, others, otherCount);
            otherOf[otherCount++] = std::uint32_t(i);
            if (otherCount == kBlock) runOthers();
            continue;
        }
        ModelBlock& b = blocks[sh.model];
        fillLane(view, rp, in[i], b.lanes, b.count, out[i]);
        b.hitOf[b.count++] = std::uint32_t(i);
        if (b.count == kBlock) run(sh.model);
    }
    for (uint model = 0; model < kModelCount; ++model)
        if (blocks[model].count > 0) run(model);
    if (otherCount > 0) runOthers();
}

} // namespace spw
#endif
