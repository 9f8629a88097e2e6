// pickLights (simd_light_pick.h): the light tree's descent SIMD-wide, compiled once per
// instruction set through foreach_target.h, and the pick's scalar ends around it.
#include "host/cpu/simd_light_pick.h"

#include "shared/lights.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/cpu/simd_light_pick.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_math-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

// The light tree's leaf for the lanes in `want` (all-ones rows) of [0, count), each from its
// point p and number u: treePick's descent (simd_math-inl.h's treeDescent), its leaf, number
// left and pmf so far into node, uLeft and pmf.
void TreeDescentLanes(const float* cdf, uint nodesAt, const simd::Vec3s& p, const Floats& u,
                      const Uints& want, size_t count, Uints& node, Floats& uLeft, Floats& pmf) {
    for (size_t i = 0; i < count; i += hn::Lanes(D())) {
        VU n;
        V left = load(u, i), m;
        treeDescent(cdf, nodesAt, load(p, i), loadMask(want, i), n, left, m);
        hn::Store(n, DU(), node.v + i);
        store(left, uLeft, i);
        store(m, pmf, i);
    }
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(TreeDescentLanes);

void pickLights(const SceneView& scene, const RenderParams& rp, const simd::Vec3s& p,
                const simd::Floats& u, const simd::Uints& want, size_t count, uint* picked,
                float* pickPdf) {
    if (rp.treeEmitters == 0u) {
        for (size_t k = 0; k < count; ++k) {
            pickPdf[k] = 0.0f;
            picked[k] = want.v[k] ? pickLight(scene, rp, vec3(p.x.v[k], p.y.v[k], p.z.v[k]), u.v[k],
                                              pickPdf[k])
                                  : kNoEmitter;
        }
        return;
    }
    const float treeShare = scene.emitterCdf[rp.treeEmitters - 1u];
    simd::Uints tree, node;
    simd::Floats uTree, uLeft, pmf;
    for (size_t k = 0; k < count; ++k) { // pickLight's choice between the tree and the CDF
        const bool t = want.v[k] && u.v[k] < treeShare;
        tree.v[k] = t ? ~0u : 0u;
        uTree.v[k] = t ? min(u.v[k] / treeShare, kOneMinusEpsilon) : 0.0f;
    }
    HWY_DYNAMIC_DISPATCH(TreeDescentLanes)
    (scene.emitterCdf, treeNodeBase(rp, 0u), p, uTree, tree, count, node, uLeft, pmf);
    for (size_t k = 0; k < count; ++k) {
        picked[k] = kNoEmitter;
        pickPdf[k] = 0.0f;
        if (!want.v[k]) continue;
        if (!tree.v[k]) {
            picked[k] =
                pickLight(scene, rp, vec3(p.x.v[k], p.y.v[k], p.z.v[k]), u.v[k], pickPdf[k]);
            continue;
        }
        float leafPmf = 0.0f;
        if (node.v[k] != kTreeRoot) {
            leafPmf = pmf.v[k];
            picked[k] = treeLeafPick(scene, rp, node.v[k], treeLinks(scene, rp, node.v[k]),
                                     uLeft.v[k], leafPmf);
        }
        pickPdf[k] = leafPmf * treeShare;
    }
}

} // namespace spw
#endif
