#include "host/scene_view/light_tree.h"

#include "host/scene/emitter_kinds.h"
#include "shared/light_tree.h"

#include <algorithm>
#include <cmath>

namespace spw {
namespace {

using dvec3 = glm::dvec3;

constexpr double kPiD = 3.14159265358979323846;

// pbrt-v4's LightBounds, in double while the tree is built: a box around the emitters, the cone
// of their emission axes (axis, its spread theta_o) and how far past it they emit (theta_e).
struct Bounds {
    dvec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};
    dvec3 axis{0.0, 0.0, 1.0};
    double thetaO = 0.0, thetaE = 0.0;
    double power = 0.0;
    bool twoSided = false;
};

Bounds emitterBounds(const Emitter& e) {
    Bounds b;
    b.power = double(e.pickPdf);
    if (e.type == kEmitterTriangle) {
        for (const vec3& p : {e.p0, e.p0 + e.e1, e.p0 + e.e2}) {
            b.lo = glm::min(b.lo, dvec3(p));
            b.hi = glm::max(b.hi, dvec3(p));
        }
        b.axis = dvec3(e.normal);
        b.thetaE = kPiD / 2; // the hemisphere about the normal
        b.twoSided = e.twoSided != 0u;
        return b;
    }
    if (e.type == kEmitterInstance) { // its world bounds; its triangles face every way
        b.lo = dvec3(e.p0);
        b.hi = dvec3(e.e1);
        b.thetaO = kPiD;
        b.thetaE = kPiD / 2;
        return b;
    }
    b.lo = b.hi = dvec3(e.p0);
    if (e.type == kEmitterSpot) { // e1: (cos outer, cos inner)
        const double inner = std::acos(std::clamp(double(e.e1.y), -1.0, 1.0));
        const double outer = std::acos(std::clamp(double(e.e1.x), -1.0, 1.0));
        b.axis = dvec3(e.normal);
        b.thetaO = inner;
        b.thetaE = std::max(outer - inner, 0.0);
    } else { // a point, or a kind this does not know: every direction
        b.thetaO = kPiD;
        b.thetaE = kPiD / 2;
    }
    return b;
}

double angleBetween(dvec3 a, dvec3 b) {
    return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
}

// The smallest cone around both cones (pbrt-v4's DirectionCone Union).
void uniteCones(const Bounds& a, const Bounds& b, Bounds& out) {
    const double d = angleBetween(a.axis, b.axis);
    if (std::min(d + b.thetaO, kPiD) <= a.thetaO) {
        out.axis = a.axis, out.thetaO = a.thetaO;
        return;
    }
    if (std::min(d + a.thetaO, kPiD) <= b.thetaO) {
        out.axis = b.axis, out.thetaO = b.thetaO;
        return;
    }
    const double theta = 0.5 * (a.thetaO + d + b.thetaO);
    const dvec3 turn = glm::cross(a.axis, b.axis);
    if (theta >= kPiD || glm::dot(turn, turn) == 0.0) {
        out.axis = a.axis, out.thetaO = kPiD;
        return;
    }
    // a's axis turned toward b's by theta - theta_a (Rodrigues, about a unit axis).
    const dvec3 k = glm::normalize(turn);
    const double r = theta - a.thetaO;
    out.axis = glm::normalize(a.axis * std::cos(r) + glm::cross(k, a.axis) * std::sin(r) +
                              k * glm::dot(k, a.axis) * (1.0 - std::cos(r)));
    out.thetaO = theta;
}

Bounds unite(const Bounds& a, const Bounds& b) {
    if (!(a.power > 0.0)) return b;
    if (!(b.power > 0.0)) return a;
    Bounds u;
    u.lo = glm::min(a.lo, b.lo);
    u.hi = glm::max(a.hi, b.hi);
    uniteCones(a, b, u);
    u.thetaE = std::max(a.thetaE, b.thetaE);
    u.power = a.power + b.power;
    u.twoSided = a.twoSided || b.twoSided;
    return u;
}

bool sameBounds(const Bounds& a, const Bounds& b) {
    return a.lo == b.lo && a.hi == b.hi && a.axis == b.axis && a.thetaO == b.thetaO &&
           a.thetaE == b.thetaE && a.twoSided == b.twoSided;
}

// The most emitters a leaf holds (all with the same bounds).
constexpr size_t kMaxLeafEmitters = 8;

float bits(uint u) {
    return glm::uintBitsToFloat(u);
}

// Builds the tree over emitters [0, count), writing each node's words into `table` as it is
// made (preorder: a node's first child follows it). Per emitter it holds only twice its box's
// centre, its place in `order` and its leaf: a node's bounds are returned up the recursion, not
// kept, so a forest of a million emissive triangles builds in tens of bytes each beside the table.
struct Builder {
    const std::vector<Emitter>& emitters;
    std::vector<dvec3> centres; // per emitter: lo + hi of its box
    std::vector<uint> order;    // emitter indices, partitioned as the build goes
    std::vector<uint> leafOf;
    std::vector<float>& table;
    size_t nodesStart; // where node 0's words start in the table
    uint nodes = 0;

    // Whether order[begin, end) is one leaf: one emitter, or a few the tree cannot tell apart.
    bool leafOfOne(size_t begin, size_t end) const {
        if (end - begin > kMaxLeafEmitters) return false;
        const Bounds first = emitterBounds(emitters[order[begin]]);
        for (size_t i = begin + 1; i < end; ++i)
            if (!sameBounds(emitterBounds(emitters[order[i]]), first)) return false;
        return true;
    }

    void write(uint node, const Bounds& nb, uint link, uint parent, uint count) {
        const dvec3 centre = 0.5 * (nb.lo + nb.hi);
        const double radius = 0.5 * glm::length(nb.hi - nb.lo);
        // Rounded up, so that the float sphere still holds every emitter.
        const float r =
            radius > 0.0 ? std::nextafter(float(radius * (1.0 + 1e-6)), INFINITY) : 0.0f;
        const float words[kTreeNodeWords] = {float(centre.x),
                                             float(centre.y),
                                             float(centre.z),
                                             r,
                                             float(nb.axis.x),
                                             float(nb.axis.y),
                                             float(nb.axis.z),
                                             float(std::cos(nb.thetaO)),
                                             float(std::sin(nb.thetaO)),
                                             float(std::cos(nb.thetaE)),
                                             float(nb.power),
                                             bits(link),
                                             bits(parent),
                                             bits(count),
                                             0.0f,
                                             0.0f};
        std::copy(words, words + kTreeNodeWords,
                  table.begin() + std::ptrdiff_t(nodesStart) +
                      std::ptrdiff_t(node) * kTreeNodeWords);
    }

    // The node over order[begin, end) and its subtree after it, `node` its index; returns its
    // bounds.
    Bounds build(size_t begin, size_t end, uint parent, uint& node) {
        node = nodes++;
        table.resize(table.size() + kTreeNodeWords);
        if (leafOfOne(begin, end)) {
            Bounds merged;
            for (size_t i = begin; i < end; ++i) {
                merged = unite(merged, emitterBounds(emitters[order[i]]));
                leafOf[order[i]] = node;
            }
            write(node, merged, kTreeLeaf | (merged.twoSided ? kTreeTwoSided : 0u) | uint(begin),
                  parent, uint(end - begin));
            return merged;
        }
        dvec3 lo(std::numeric_limits<double>::max()), hi(-lo);
        for (size_t i = begin; i < end; ++i) {
            lo = glm::min(lo, 0.5 * centres[order[i]]);
            hi = glm::max(hi, 0.5 * centres[order[i]]);
        }
        const dvec3 extent = hi - lo;
        const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0
                         : extent.y >= extent.z                       ? 1
                                                                      : 2;
        const size_t mid = begin + (end - begin) / 2;
        std::nth_element(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(mid),
                         order.begin() + std::ptrdiff_t(end), [&](uint a, uint b) {
                             const double ca = centres[a][axis], cb = centres[b][axis];
                             return ca < cb || (ca == cb && a < b);
                         });
        uint first, second;
        const Bounds a = build(begin, mid, node, first);
        const Bounds b = build(mid, end, node, second);
        const Bounds merged = unite(a, b);
        write(node, merged, (merged.twoSided ? kTreeTwoSided : 0u) | second, parent, 0u);
        return merged;
    }
};

} // namespace

bool inLightTree(const Emitter& e) {
    const EmitterKindInfo* kind = emitterKind(e.type);
    return kind && (kind->flags & (kLightSurface | kLightTakesPosition | kLightInstanced)) != 0u;
}

bool lightTreeChangesPicks(const std::vector<Emitter>& emitters, uint count) {
    if (count < 2) return false;
    const Bounds first = emitterBounds(emitters[0]);
    for (uint i = 1; i < count; ++i)
        if (!sameBounds(emitterBounds(emitters[i]), first)) return true;
    return false;
}

void appendLightTree(const std::vector<Emitter>& emitters, uint count, std::vector<float>& table) {
    // The words: each emitter's leaf, the leaves' members (emitter, power), then the nodes, at
    // most 2 count - 1 (a binary tree over count leaves), reserved so that no growth copies them.
    const size_t start = table.size();
    table.reserve(start + 3 * size_t(count) + (2 * size_t(count) - 1) * kTreeNodeWords);
    table.resize(start + 3 * size_t(count));
    Builder b{emitters, {}, {}, std::vector<uint>(count, 0u), table, table.size()};
    b.centres.reserve(count);
    b.order.reserve(count);
    for (uint i = 0; i < count; ++i) {
        const Bounds e = emitterBounds(emitters[i]);
        b.centres.push_back(e.lo + e.hi);
        b.order.push_back(i);
    }
    uint root;
    b.build(0, count, kTreeRoot, root);
    for (uint i = 0; i < count; ++i) {
        table[start + i] = bits(b.leafOf[i]);
        table[start + count + 2 * i] = bits(b.order[i]);
        table[start + count + 2 * i + 1] = emitters[b.order[i]].pickPdf;
    }
}

} // namespace spw
