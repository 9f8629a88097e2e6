#include "host/obj_mesh.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

namespace spw {
namespace {

// tinyobjloader does not report line numbers: find the line of the n-th vertex statement.
int lineOfVertex(const std::string& path, size_t vertexIndex) {
    std::ifstream in(path);
    std::string line;
    size_t seen = 0;
    for (int lineNo = 1; std::getline(in, line); ++lineNo) {
        size_t i = line.find_first_not_of(" \t");
        if (i != std::string::npos && line.compare(i, 2, "v ") == 0 && seen++ == vertexIndex) return lineNo;
    }
    return 0;
}

// tinyobjloader reads a number it cannot parse ("nan", "inf", "1x") as 0 without a word: check
// every coordinate of the v, vn and vt statements first, naming the OBJ file and line.
void checkCoordinates(const std::string& path, const std::string& text) {
    auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    const char* p = text.c_str();
    const char* const end = p + text.size();
    for (int lineNo = 1; p < end; ++lineNo) {
        const char* eol = std::find(p, end, '\n');
        const char* stop = std::find(p, eol, '#');
        while (p < stop && blank(*p)) ++p;
        const char* word = p;
        while (p < stop && !blank(*p)) ++p;
        const std::string statement(word, p);
        if (statement == "v" || statement == "vn" || statement == "vt") {
            while (true) {
                while (p < stop && blank(*p)) ++p;
                if (p == stop) break;
                const char* start = p;
                while (p < stop && !blank(*p)) ++p;
                const std::string token(start, p);
                char* parsed = nullptr;
                const double v = std::strtod(token.c_str(), &parsed);
                if (parsed != token.c_str() + token.size() || !std::isfinite(v))
                    throw SceneError(path, lineNo, "'" + statement + "' coordinate '" + token +
                                                       "' is not a finite number");
            }
        }
        p = eol + (eol < end ? 1 : 0);
    }
}

} // namespace

Mesh loadObjMesh(const std::string& path, const mat4& objectToWorld, const std::string& sceneFile,
                 int sceneLine) {
    tinyobj::ObjReaderConfig cfg;
    cfg.triangulate = true;
    cfg.vertex_color = false;
    cfg.mtl_search_path = "";
    tinyobj::ObjReader reader;
    // Materials are ignored (shaders come from the scene): parse the geometry only.
    std::ifstream file(path);
    std::stringstream text;
    text << file.rdbuf();
    if (file) checkCoordinates(path, text.str());
    if (!file || !reader.ParseFromString(text.str(), "", cfg)) {
        std::string why = reader.Error();
        while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
        throw SceneError(sceneFile, sceneLine, "cannot read OBJ file '" + path + "': " + why);
    }
    const tinyobj::attrib_t& a = reader.GetAttrib();
    for (size_t i = 0; i < a.vertices.size(); ++i)
        if (!std::isfinite(a.vertices[i]))
            throw SceneError(path, lineOfVertex(path, i / 3), "vertex coordinate is not a finite number");
    for (size_t i = 0; i < a.normals.size(); ++i)
        if (!std::isfinite(a.normals[i]))
            throw SceneError(sceneFile, sceneLine, "OBJ file '" + path + "' has a non-finite normal");

    Mesh mesh;
    mesh.name = path;
    const mat3 normalXf = glm::transpose(glm::inverse(mat3(objectToWorld)));
    bool hasNormals = !a.normals.empty();
    bool hasUvs = !a.texcoords.empty();
    // One mesh vertex per distinct (position, normal, uv) triple of the OBJ.
    std::map<std::tuple<int, int, int>, uint> remap;
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        const auto& idx = shape.mesh.indices;
        for (size_t f = 0; f + 2 < idx.size(); f += 3) {
            uvec3 tri;
            for (int k = 0; k < 3; ++k) {
                const tinyobj::index_t& ix = idx[f + k];
                auto key = std::make_tuple(ix.vertex_index, hasNormals ? ix.normal_index : -1,
                                           hasUvs ? ix.texcoord_index : -1);
                auto [it, inserted] = remap.try_emplace(key, uint(mesh.positions.size()));
                if (inserted) {
                    vec3 p(a.vertices[3 * ix.vertex_index], a.vertices[3 * ix.vertex_index + 1],
                           a.vertices[3 * ix.vertex_index + 2]);
                    const vec3 world = vec3(objectToWorld * vec4(p, 1.0f));
                    // Finite in the file but not after the object's transform.
                    if (!std::isfinite(world.x) || !std::isfinite(world.y) || !std::isfinite(world.z))
                        throw SceneError(path, lineOfVertex(path, size_t(ix.vertex_index)),
                                         "vertex is not a finite number after the object's transform (scene " +
                                             sceneFile + ":" + std::to_string(sceneLine) + ")");
                    mesh.positions.push_back(world);
                    if (hasNormals) {
                        vec3 n(0.0f);
                        if (ix.normal_index >= 0)
                            n = vec3(a.normals[3 * ix.normal_index], a.normals[3 * ix.normal_index + 1],
                                     a.normals[3 * ix.normal_index + 2]);
                        n = normalXf * n;
                        float len = glm::length(n);
                        mesh.normals.push_back(len > 0.0f ? n / len : vec3(0.0f));
                    }
                    if (hasUvs) {
                        vec2 uv(0.0f);
                        if (ix.texcoord_index >= 0)
                            uv = vec2(a.texcoords[2 * ix.texcoord_index], a.texcoords[2 * ix.texcoord_index + 1]);
                        mesh.uvs.push_back(uv);
                    }
                }
                tri[k] = it->second;
            }
            // Zero area as the renderer sees it: it normalises cross(e1, e2) in float, so |c|^2 must
            // be a normal float (not 0, not a denormal that flush-to-zero turns into 0).
            vec3 e1 = mesh.positions[tri.y] - mesh.positions[tri.x];
            vec3 e2 = mesh.positions[tri.z] - mesh.positions[tri.x];
            vec3 c = glm::cross(e1, e2);
            const float c2 = glm::dot(c, c);
            if (std::isinf(c2) || std::isnan(c2))
                throw SceneError(sceneFile, sceneLine, "OBJ file '" + path + "' has a triangle too large for float "
                                                       "(its normal overflows): edges must stay below about 1e9");
            if (!(c2 >= std::numeric_limits<float>::min())) {
                ++mesh.droppedTriangles;
                continue;
            }
            mesh.triangles.push_back(tri);
        }
    }
    return mesh;
}

} // namespace spw
