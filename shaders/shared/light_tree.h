// Many-light sampling: a binary tree over the emitters at a place (triangles, point and spot
// lights), each node bounding its emitters' positions (a sphere), the directions they emit in
// (a cone, as pbrt-v4's LightBounds) and their power. Next-event estimation walks it from the
// root, going to each child with probability proportional to an importance that bounds what
// the child's lights can send to the shading point: power x the best cosine the cones allow /
// squared distance (Conty Estevez and Kulla 2018; pbrt-v4's BVHLightSampler). The importance
// takes the shading point alone, not its normal, so that a ray that hits an emitter can recompute
// the probability of having picked it from the ray's origin (MIS, shared/path.h).
//
// A leaf holds one emitter, or a few whose bounds are the same (the two triangles of a
// rectangle), picked among by power: no importance tells them apart.
//
// The tree lives in the emitter table behind the CDF (host/scene_view/lights.cpp builds it):
// from rp.emitterCount, each tree emitter's leaf (rp.treeEmitters words: emitters 0 .. n-1 are
// the tree's, the lights at infinity follow them), the leaves' members (rp.treeEmitters pairs
// of words: the emitter, its power), then the nodes, kTreeNodeWords words each. A node's first
// child is the node after it; its second child, or a leaf's first member, is named by its links
// word.
#ifndef SPILLWAY_SHARED_LIGHT_TREE_H
#define SPILLWAY_SHARED_LIGHT_TREE_H
#include "scene_access.h"

SHARED_BEGIN

// A node's words: centre xyz, radius, cone axis xyz, cos and sin of the cone's spread (theta_o),
// cos of the emission's spread beyond it (theta_e), power (a share of the total), links, parent,
// a leaf's member count, and two unused: 16 words, 64 bytes.
const uint kTreeNodeWords = 16u;
const uint kTreeLeaf = 0x80000000u;     // links: a leaf, whose low bits name its first member
const uint kTreeTwoSided = 0x40000000u; // links: the cone holds for -axis as well
const uint kTreeIndex = 0x3FFFFFFFu;    // links: the second child, or the leaf's first member
const uint kTreeRoot = 0xFFFFFFFFu;     // parent of the root

SHARED_FN uint treeNodeBase(RenderParams rp, uint node) {
    return rp.emitterCount + 3u * rp.treeEmitters + node * kTreeNodeWords;
}

// Member k's word (0: the emitter, 1: its power) of the leaves' member list.
SHARED_FN uint treeMemberBase(RenderParams rp, uint member) {
    return rp.emitterCount + rp.treeEmitters + 2u * member;
}

SHARED_FN uint treeLinks(SCENE_PARAM RenderParams rp, uint node) {
    return floatBitsToUint(EMITTER_CDF(treeNodeBase(rp, node) + 11u));
}

// An upper bound, up to the shared factor of the emitters' total power, of what the node's
// emitters send toward p; 0 when none can reach it. Never infinite: the squared distance is at
// least the node's squared radius and 1e-30.
// Conty Estevez and Kulla 2018, eq. 3, without the receiver's cosine: power x cos(theta') /
// d^2, theta' = max(0, theta_w - theta_o - theta_b) the least angle between the direction from
// the node toward p and any emitter's axis, theta_b the angle the node's sphere subtends at p;
// 0 where theta' is beyond theta_e. Its SIMD form: host/simd/simd_math-inl.h's treeImportance.
SHARED_FN float treeImportance(SCENE_PARAM RenderParams rp, uint node, vec3 p) {
    uint b = treeNodeBase(rp, node);
    float power = EMITTER_CDF(b + 10u);
    if (!(power > 0.0f)) return 0.0f;
    vec3 d = p - vec3(EMITTER_CDF(b), EMITTER_CDF(b + 1u), EMITTER_CDF(b + 2u));
    float radius = EMITTER_CDF(b + 3u);
    float r2 = radius * radius;
    float d2 = dot(d, d);
    float cosP = 1.0f; // cos(theta'), 1 while p is inside the sphere or the cone of axes
    if (d2 > r2) {
        vec3 axis = vec3(EMITTER_CDF(b + 4u), EMITTER_CDF(b + 5u), EMITTER_CDF(b + 6u));
        float cosO = EMITTER_CDF(b + 7u);
        float invD = inversesqrt(d2);
        float cosW = dot(axis, d) * invD;
        if ((floatBitsToUint(EMITTER_CDF(b + 11u)) & kTreeTwoSided) != 0u) cosW = abs(cosW);
        if (cosW < cosO) {
            // theta_x = theta_w - theta_o, then less theta_b.
            float sinO = EMITTER_CDF(b + 8u);
            float sinW = sqrt(max(0.0f, 1.0f - cosW * cosW));
            float cosX = cosW * cosO + sinW * sinO;
            float sinX = max(sinW * cosO - cosW * sinO, 0.0f);
            float sinB = min(radius * invD, 1.0f);
            float cosB = sqrt(max(0.0f, 1.0f - sinB * sinB));
            cosP = cosX > cosB ? 1.0f : cosX * cosB + sinX * sinB;
        }
        if (!(cosP > EMITTER_CDF(b + 9u))) return 0.0f;
    }
    return power * cosP / max(max(d2, r2), 1e-30f);
}

// Among leaf `node`'s members (links: its links word), the one u picks in proportion to power,
// its probability multiplied into pmf.
SHARED_FN uint treeLeafPick(SCENE_PARAM RenderParams rp, uint node, uint links, float u,
                            INOUT(float) pmf) {
    uint first = links & kTreeIndex;
    uint count = floatBitsToUint(EMITTER_CDF(treeNodeBase(rp, node) + 13u));
    float total = 0.0f;
    for (uint k = 0u; k < count; ++k)
        total += EMITTER_CDF(treeMemberBase(rp, first + k) + 1u);
    float target = u * total;
    float running = 0.0f;
    for (uint k = 0u; k < count; ++k) {
        float power = EMITTER_CDF(treeMemberBase(rp, first + k) + 1u);
        running += power;
        if (target < running || k + 1u == count) {
            pmf *= power / total;
            return floatBitsToUint(EMITTER_CDF(treeMemberBase(rp, first + k)));
        }
    }
    pmf = 0.0f;
    return kNoEmitter;
}

// The share of leaf `node`'s power that its member `emitter` has: the probability that
// treeLeafPick takes it.
SHARED_FN float treeLeafPmf(SCENE_PARAM RenderParams rp, uint node, uint emitter) {
    uint first = treeLinks(SCENE_ARG rp, node) & kTreeIndex;
    uint count = floatBitsToUint(EMITTER_CDF(treeNodeBase(rp, node) + 13u));
    float total = 0.0f;
    float mine = 0.0f;
    for (uint k = 0u; k < count; ++k) {
        float power = EMITTER_CDF(treeMemberBase(rp, first + k) + 1u);
        total += power;
        if (floatBitsToUint(EMITTER_CDF(treeMemberBase(rp, first + k))) == emitter) mine = power;
    }
    return total > 0.0f ? mine / total : 0.0f;
}

// The tree emitter picked for shading point p with u uniform in [0, 1), and its probability
// (pmf; 0 and kNoEmitter when no emitter can reach p). Its SIMD form, up to the leaf, is
// host/simd/simd_math-inl.h's treeDescent (checked through the cpu engine's shading,
// SimdShading.HitsUnderALightTreeAreShadeSurfaceToTheBit).
SHARED_FN uint treePick(SCENE_PARAM RenderParams rp, vec3 p, float u, OUT(float) pmf) {
    uint node = 0u;
    pmf = 1.0f;
    for (uint depth = 0u; depth < 64u; ++depth) {
        uint links = treeLinks(SCENE_ARG rp, node);
        if ((links & kTreeLeaf) != 0u) return treeLeafPick(SCENE_ARG rp, node, links, u, pmf);
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
    float pmf = treeLeafPmf(SCENE_ARG rp, node, emitter);
    for (uint depth = 0u; depth < 64u; ++depth) {
        uint parent = floatBitsToUint(EMITTER_CDF(treeNodeBase(rp, node) + 12u));
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
