// Wavefront OBJ meshes through tinyobjloader, transformed to world space.
#pragma once

#include "host/scene.h"

namespace spw {

// Loads `path`, applies `objectToWorld` to positions (and its inverse transpose to normals),
// triangulates polygons and drops zero-area triangles (counted in Mesh::droppedTriangles).
// Errors name the OBJ file and line (a non-finite coordinate) or, for a file tinyobjloader
// cannot read, the scene line that references it.
Mesh loadObjMesh(const std::string& path, const mat4& objectToWorld, const std::string& sceneFile,
                 int sceneLine);

} // namespace spw
