// Many-light sampling: a binary tree over the emitters at a place (triangles, point and spot
// lights), each node bounding its emitters' positions (a sphere), the directions they emit in
// (a cone, as pbrt-v4's LightBounds) and their power. Next-event estimation walks it from the
// root, going to each child with probability proportional to an importance that bounds what
// the child's lights can send to the shading point: power x the best cosine the cones allow /
// squared distance (Conty Estevez and Kulla 2018; pbrt-v4's BVHLightSampler). The importance
// takes the shading point alone, not its normal, so that a ray that hits an emitter can recompute
// the probability of having picked it from the ray's origin (MIS, shared/path.h).
//
// The tree lives in the emitter table behind the CDF (host/scene_view/lights.cpp builds it):
// from rp.emitterCount, each tree emitter's leaf (rp.treeEmitters words: emitters 0 .. n-1 are
// the tree's, the lights at infinity follow them), then the nodes, kTreeNodeWords words each.
// A node's first child is the node after it; its second child is named by its links word.
#ifndef SPILLWAY_SHARED_LIGHT_TREE_H
#define SPILLWAY_SHARED_LIGHT_TREE_H
#include "scene_access.h"

SHARED_BEGIN

// A node's words: centre xyz, radius, cone axis xyz, cos of the cone's spread (theta_o), cos of
// the emission's spread beyond it (theta_e), power (a share of the total), links, parent.
const uint kTreeNodeWords = 12u;
const uint kTreeLeaf = 0x80000000u;     // links: a leaf, whose low bits name its emitter
const uint kTreeTwoSided = 0x40000000u; // links: the cone holds for -axis as well
const uint kTreeIndex = 0x3FFFFFFFu;    // links: the second child, or the leaf's emitter
const uint kTreeRoot = 0xFFFFFFFFu;     // parent of the root

SHARED_FN uint treeNodeBase(RenderParams rp, uint node) {
    return rp.emitterCount + rp.treeEmitters + node * kTreeNodeWords;
}

SHARED_FN uint treeLinks(SCENE_PARAM RenderParams rp, uint node) {
    return floatBitsToUint(EMITTER_CDF(treeNodeBase(rp, node) + 10u));
}

// cos(max(0, a - b)) from the cosines and sines of a and b (angles in [0, pi]).
SHARED_FN float cosOfDifferenceClamped(float cosA, float sinA, float cosB, float sinB) {
    if (cosA > cosB) return 1.0f;
    return cosA * cosB + sinA * sinB;
}

// An upper bound, up to the shared factor of the emitters' total power, of what the node's
// emitters send toward p; 0 when none can reach it. Never infinite: the squared distance is at
// least the node's squared radius and 1e-30.
// Conty Estevez and Kulla 2018, eq. 3, without the receiver's cosine.
SHARED_FN float treeImportance(SCENE_PARAM RenderParams rp, uint node, vec3 p) {
    uint b = treeNodeBase(rp, node);
    float power = EMITTER_CDF(b + 9u);
    if (!(power > 0.0f)) return 0.0f;
    vec3 d = p - vec3(EMITTER_CDF(b), EMITTER_CDF(b + 1u), EMITTER_CDF(b + 2u));
    float radius = EMITTER_CDF(b + 3u);
    float r2 = radius * radius;
    float d2 = dot(d, d);
    float cosP = 1.0f; // the best cosine any emitter's cone allows toward p
    if (d2 > r2) {
        vec3 axis = vec3(EMITTER_CDF(b + 4u), EMITTER_CDF(b + 5u), EMITTER_CDF(b + 6u));
        float cosO = EMITTER_CDF(b + 7u);
        float cosW = dot(axis, d) / sqrt(d2); // the axis against the direction from the centre
        if ((floatBitsToUint(EMITTER_CDF(b + 10u)) & kTreeTwoSided) != 0u) cosW = abs(cosW);
        float sinW = sqrt(max(0.0f, 1.0f - cosW * cosW));
        float sinO = sqrt(max(0.0f, 1.0f - cosO * cosO));
        // theta_x = theta_w - theta_o: the direction to p outside the cone of emission axes...
        float cosX = cosOfDifferenceClamped(cosW, sinW, cosO, sinO);
        float sinX = cosW > cosO ? 0.0f : sinW * cosO - cosW * sinO;
        // ... less theta_b, the angle the node's sphere subtends at p.
        float sin2B = r2 / d2;
        float cosB = sqrt(max(0.0f, 1.0f - sin2B));
        cosP = cosOfDifferenceClamped(cosX, max(sinX, 0.0f), cosB, sqrt(sin2B));
        if (!(cosP > EMITTER_CDF(b + 8u))) return 0.0f;
    }
    return power * cosP / max(max(d2, r2), 1e-30f);
}

// The tree emitter picked for shading point p with u uniform in [0, 1), and its probability
// (pmf; 0 and kNoEmitter when no emitter can reach p).
SHARED_FN uint treePick(SCENE_PARAM RenderParams rp, vec3 p, float u, OUT(float) pmf) {
    uint node = 0u;
    pmf = 1.0f;
    for (uint depth = 0u; depth < 64u; ++depth) {
        uint links = treeLinks(SCENE_ARG rp, node);
        if ((links & kTreeLeaf) != 0u) return links & kTreeIndex;
        uint second = links & kTreeIndex;
        float i0 = treeImportance(SCENE_ARG rp, node + 1u, p);
        float i1 = treeImportance(SCENE_ARG rp, second, p);
        float sum = i0 + i1;
        if (!(sum > 0.0f)) break;
        float p0 = i0 / sum;
        if (u < p0) {
            u = min(u / p0, kOneMinusEpsilon);
            pmf *= p0;
            node = node + 1u;
        } else {
            u = min((u - p0) / (1.0f - p0), kOneMinusEpsilon);
            pmf *= i1 / sum;
            node = second;
        }
    }
    pmf = 0.0f;
    return kNoEmitter;
}

// The probability that treePick picks tree emitter `emitter` for shading point p: the choices
// on the way from its leaf up to the root.
SHARED_FN float treePmf(SCENE_PARAM RenderParams rp, uint emitter, vec3 p) {
    uint node = floatBitsToUint(EMITTER_CDF(rp.emitterCount + emitter));
    float pmf = 1.0f;
    for (uint depth = 0u; depth < 64u; ++depth) {
        uint parent = floatBitsToUint(EMITTER_CDF(treeNodeBase(rp, node) + 11u));
        if (parent == kTreeRoot) return pmf;
        uint second = treeLinks(SCENE_ARG rp, parent) & kTreeIndex;
        float i0 = treeImportance(SCENE_ARG rp, parent + 1u, p);
        float i1 = treeImportance(SCENE_ARG rp, second, p);
        float sum = i0 + i1;
        if (!(sum > 0.0f)) return 0.0f;
        pmf *= (node == second ? i1 : i0) / sum;
        node = parent;
    }
    return 0.0f;
}

SHARED_END
#endif
