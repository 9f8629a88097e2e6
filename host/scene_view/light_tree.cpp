#include "host/scene_view/light_tree.h"

#include "host/scene/emitter_kinds.h"
#include "shared/light_tree.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

struct Builder {
    const std::vector<Bounds>& leaves;
    std::vector<uint> order; // emitter indices, partitioned as the build goes
    std::vector<Bounds> nodes;
    std::vector<uint> links, parents, counts, leafOf;

    // Whether order[begin, end) is one leaf: one emitter, or a few the tree cannot tell apart.
    bool leafOfOne(size_t begin, size_t end) const {
        if (end - begin > kMaxLeafEmitters) return false;
        for (size_t i = begin + 1; i < end; ++i)
            if (!sameBounds(leaves[order[i]], leaves[order[begin]])) return false;
        return true;
    }

    // The node over order[begin, end), and its subtree after it; returns its index.
    uint build(size_t begin, size_t end, uint parent) {
        const uint node = uint(nodes.size());
        nodes.emplace_back();
        links.push_back(0u);
        parents.push_back(parent);
        counts.push_back(0u);
        if (leafOfOne(begin, end)) {
            Bounds merged;
            for (size_t i = begin; i < end; ++i) {
                merged = unite(merged, leaves[order[i]]);
                leafOf[order[i]] = node;
            }
            nodes[node] = merged;
            links[node] = kTreeLeaf | (merged.twoSided ? kTreeTwoSided : 0u) | uint(begin);
            counts[node] = uint(end - begin);
            return node;
        }
        dvec3 lo(std::numeric_limits<double>::max()), hi(-lo);
        for (size_t i = begin; i < end; ++i) {
            const Bounds& b = leaves[order[i]];
            lo = glm::min(lo, 0.5 * (b.lo + b.hi));
            hi = glm::max(hi, 0.5 * (b.lo + b.hi));
        }
        const dvec3 extent = hi - lo;
        const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0
                         : extent.y >= extent.z                       ? 1
                                                                      : 2;
        const size_t mid = begin + (end - begin) / 2;
        std::nth_element(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(mid),
                         order.begin() + std::ptrdiff_t(end), [&](uint a, uint b) {
                             const double ca = leaves[a].lo[axis] + leaves[a].hi[axis];
                             const double cb = leaves[b].lo[axis] + leaves[b].hi[axis];
                             return ca < cb || (ca == cb && a < b);
                         });
        const uint first = build(begin, mid, node);
        const uint second = build(mid, end, node);
        const Bounds merged = unite(nodes[first], nodes[second]);
        nodes[node] = merged;
        links[node] = (merged.twoSided ? kTreeTwoSided : 0u) | second;
        return node;
    }
};

float bits(uint u) {
    return glm::uintBitsToFloat(u);
}

} // namespace

bool inLightTree(const Emitter& e) {
    const EmitterKindInfo* kind = emitterKind(e.type);
    return kind && (kind->flags & (kLightSurface | kLightTakesPosition)) != 0u;
}

bool lightTreeChangesPicks(const std::vector<Emitter>& emitters, uint count) {
    if (count < 2) return false;
    const Bounds first = emitterBounds(emitters[0]);
    for (uint i = 1; i < count; ++i)
        if (!sameBounds(emitterBounds(emitters[i]), first)) return true;
    return false;
}

void appendLightTree(const std::vector<Emitter>& emitters, uint count, std::vector<float>& table) {
    std::vector<Bounds> leaves;
    for (uint i = 0; i < count; ++i)
        leaves.push_back(emitterBounds(emitters[i]));
    Builder b{leaves, {}, {}, {}, {}, {}, std::vector<uint>(count, 0u)};
    for (uint i = 0; i < count; ++i)
        b.order.push_back(i);
    b.build(0, count, kTreeRoot);
    for (uint node : b.leafOf)
        table.push_back(bits(node));
    for (uint e : b.order)
        table.insert(table.end(), {bits(e), emitters[e].pickPdf});
    const size_t start = table.size();
    for (size_t n = 0; n < b.nodes.size(); ++n) {
        const Bounds& nb = b.nodes[n];
        const dvec3 centre = 0.5 * (nb.lo + nb.hi);
        const double radius = 0.5 * glm::length(nb.hi - nb.lo);
        // Rounded up, so that the float sphere still holds every emitter.
        const float r =
            radius > 0.0 ? std::nextafter(float(radius * (1.0 + 1e-6)), INFINITY) : 0.0f;
        table.insert(table.end(),
                     {float(centre.x), float(centre.y), float(centre.z), r, float(nb.axis.x),
                      float(nb.axis.y), float(nb.axis.z), float(std::cos(nb.thetaO)),
                      float(std::sin(nb.thetaO)), float(std::cos(nb.thetaE)), float(nb.power),
                      bits(b.links[n]), bits(b.parents[n]), bits(b.counts[n]), 0.0f, 0.0f});
    }
    if (table.size() - start != b.nodes.size() * kTreeNodeWords)
        throw std::logic_error("light tree: a node's words are not kTreeNodeWords");
}

} // namespace spw
