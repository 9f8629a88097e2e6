// The light tree that next-event estimation walks among the emitters at a place
// (shared/light_tree.h): built once per scene from the emitters, as words the kernels read
// behind the emitter CDF.
#pragma once

#include "shared/types.h"

#include <vector>

namespace spw {

// Whether emitter e belongs in the light tree: it has a place (a triangle, a point or a spot
// light), not only a direction (a directional light, the environment).
bool inLightTree(const Emitter& e);

// Whether a tree over emitters [0, count) picks differently from their power CDF: unless every
// one has the same bounds (the two triangles of a rectangular quad light do), where each node's
// importance is its power times one factor and the tree only costs time.
bool lightTreeChangesPicks(const std::vector<Emitter>& emitters, uint count);

// Appends to `table` the words of shared/light_tree.h for emitters [0, count) (each inLightTree,
// its pickPdf its share of the power): each emitter's leaf, the leaves' members, then the nodes.
// Splits at the median of the emitters' centres along the widest axis, so the tree is balanced: a
// depth of log2(count) rounded up.
void appendLightTree(const std::vector<Emitter>& emitters, uint count, std::vector<float>& table);

} // namespace spw
