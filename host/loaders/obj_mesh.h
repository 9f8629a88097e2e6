// Wavefront OBJ meshes, transformed to the scene's camera-relative world (host/scene/scene.h).
//
// tinyobjloader parses and triangulates, but it passes over what it cannot read: a number it
// cannot parse becomes 0, an unknown statement is skipped, an index naming no element is kept
// and later read out of bounds. So the text is first checked statement by statement here, with
// its line number: only the statements of the OBJ format, only printable text, finite
// coordinates, face indices that name existing elements, at least three vertices a face and at
// least one face a file. That pass also keeps the positions in double, so that the object's
// transform and the shift to the camera happen before the one rounding to float.
#pragma once

#include "host/scene/scene.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace spw {

// Loads `path`, maps positions by `objectToWorld` and then subtracts `origin` (both in double),
// maps normals by the inverse transpose, triangulates polygons and drops zero-area triangles
// (counted in Mesh::droppedTriangles). Throws SceneError naming the OBJ file and line for a
// problem in the file, or the scene line (`sceneFile`:`sceneLine`) that references it.
Mesh loadObjMesh(const std::string& path, const glm::dmat4& objectToWorld, const glm::dvec3& origin,
                 const std::string& sceneFile, int sceneLine);

} // namespace spw
