#include "host/loaders/obj_mesh.h"

#include <tiny_obj_loader.h>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

namespace spw {
namespace {

// Every statement of the OBJ format (Wavefront's specification, appendix B1), geometry and
// free-form alike. tinyobjloader reads v, vt, vn, f, l, p, g, o, s, mtllib and usemtl and
// skips the rest, as Spillway does; a word outside this list is not OBJ.
const char* const kStatements[] = {
    "v",    "vt",         "vn",        "vp",     "f",      "l",      "p",        "g",
    "o",    "s",          "mtllib",    "usemtl", "maplib", "usemap", "cstype",   "deg",
    "bmat", "step",       "curv",      "curv2",  "surf",   "parm",   "trim",     "hole",
    "scrv", "sp",         "end",       "con",    "mg",     "bevel",  "c_interp", "d_interp",
    "lod",  "shadow_obj", "trace_obj", "ctech",  "stech",  "call",   "csh"};

bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// A decimal number as tinyobjloader parses one: sign, digits with an optional point, exponent.
// strtod alone would also take hex floats, "inf" and "nan", which tinyobjloader reads otherwise.
bool isDecimal(const std::string& s) {
    size_t i = 0, n = s.size();
    if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
    size_t digits = 0;
    while (i < n && std::isdigit((unsigned char)s[i]))
        ++i, ++digits;
    if (i < n && s[i] == '.') {
        ++i;
        while (i < n && std::isdigit((unsigned char)s[i]))
            ++i, ++digits;
    }
    if (digits == 0) return false;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
        size_t exp = 0;
        while (i < n && std::isdigit((unsigned char)s[i]))
            ++i, ++exp;
        if (exp == 0) return false;
    }
    return i == n;
}

// What the checking pass keeps: positions in double with their lines, and the element counts.
struct ObjText {
    std::string clean; // the text with comments blanked out: what tinyobjloader parses
    std::vector<glm::dvec3> positions;
    std::vector<int> positionLines;
    size_t normals = 0, uvs = 0, faces = 0;
};

class ObjChecker {
  public:
    ObjChecker(const std::string& path, ObjText& out) : path_(path), out_(out) {}

    void check(const std::string& text) {
        out_.clean = text;
        std::string& t = out_.clean;
        for (size_t i = 0; i < t.size(); ++i) {
            const unsigned char c = (unsigned char)t[i];
            if ((c < 0x20 && c != '\n' && !isBlank(char(c))) || c == 0x7F) {
                const int line =
                    int(std::count(t.begin(), t.begin() + std::ptrdiff_t(i), '\n')) + 1;
                char hex[8];
                std::snprintf(hex, sizeof hex, "0x%02X", c);
                fail(line, std::string("byte ") + hex + " is not text: this is not an OBJ file");
            }
        }
        size_t at = 0;
        for (int line = 1; at < t.size(); ++line) {
            size_t eol = t.find('\n', at);
            if (eol == std::string::npos) eol = t.size();
            // A comment runs to the end of its line; look for it on this line only (a search
            // to the end of the file from every line made reading quadratic in its size).
            const auto end = t.begin() + std::ptrdiff_t(eol);
            std::fill(std::find(t.begin() + std::ptrdiff_t(at), end, '#'), end, ' ');
            statement(line, tokens(t, at, eol));
            at = eol + 1;
        }
        // Positive indices may name elements defined later in the file: check them at the end.
        for (int k = 0; k < 3; ++k)
            if (maxIndex_[k] > (long long)count(k))
                fail(maxIndexLine_[k], std::string("index ") + std::to_string(maxIndex_[k]) +
                                           " names no " + kKindNames[k] + ": the file has " +
                                           std::to_string(count(k)));
    }

  private:
    static constexpr const char* kKindNames[3] = {"vertex ('v')", "texture coordinate ('vt')",
                                                  "normal ('vn')"};

    [[noreturn]] void fail(int line, const std::string& message) const {
        throw SceneError(path_, line, message);
    }

    static std::vector<std::string> tokens(const std::string& t, size_t at, size_t eol) {
        std::vector<std::string> words;
        while (at < eol) {
            while (at < eol && isBlank(t[at]))
                ++at;
            const size_t start = at;
            while (at < eol && !isBlank(t[at]))
                ++at;
            if (at > start) words.emplace_back(t, start, at - start);
        }
        return words;
    }

    size_t count(int kind) const {
        return kind == 0 ? out_.positions.size() : kind == 1 ? out_.uvs : out_.normals;
    }

    void numbers(int line, const std::vector<std::string>& w, size_t lo, size_t hi,
                 double* values) const {
        const size_t n = w.size() - 1;
        if (n < lo || n > hi)
            fail(line, "'" + w[0] + "' takes " +
                           (lo == hi ? std::to_string(lo)
                                     : std::to_string(lo) + " to " + std::to_string(hi)) +
                           " numbers, not " + std::to_string(n));
        for (size_t i = 1; i < w.size(); ++i) {
            const double v = std::strtod(w[i].c_str(), nullptr);
            if (!isDecimal(w[i]) || !std::isfinite(v))
                fail(line, "'" + w[0] + "' coordinate '" + w[i] + "' is not a finite number");
            if (values && i <= 3) values[i - 1] = v;
        }
    }

    // One index of a face, line or point: 1-based, or negative counting back from the last
    // element defined so far; 0 and anything else naming no element is an error.
    void index(int line, const std::string& text, int kind) {
        errno = 0;
        char* end = nullptr;
        const long long v = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || *end != '\0' ||
            (!std::isdigit((unsigned char)text[0]) && text[0] != '-' && text[0] != '+'))
            fail(line, "'" + text + "' is not an index");
        const long long have = (long long)count(kind);
        if (v == 0)
            fail(line,
                 std::string("index 0 names no ") + kKindNames[kind] + ": indices start at 1");
        if (errno == ERANGE || v < -have || v > std::numeric_limits<int>::max())
            fail(line,
                 std::string("index ") + text + " names no " + kKindNames[kind] + ": " +
                     (v < 0 ? std::to_string(have) + " defined before this line" : "out of range"));
        if (v > maxIndex_[kind]) maxIndex_[kind] = v, maxIndexLine_[kind] = line;
    }

    // "v", "v/vt", "v//vn" or "v/vt/vn" (faces); lines and points take "v" or "v/vt".
    void reference(int line, const std::string& ref, bool face) {
        std::string part[3];
        int parts = 0;
        size_t at = 0;
        while (parts < 3) {
            const size_t slash = ref.find('/', at);
            part[parts++] =
                ref.substr(at, slash == std::string::npos ? std::string::npos : slash - at);
            if (slash == std::string::npos) break;
            at = slash + 1;
            if (parts == 3) fail(line, "'" + ref + "' has more than three indices");
        }
        if (!face && parts == 3) fail(line, "'" + ref + "': a line or point takes no normal index");
        index(line, part[0], 0);
        if (parts >= 2 && !(parts == 3 && part[1].empty())) index(line, part[1], 1);
        if (parts == 3) index(line, part[2], 2);
    }

    void statement(int line, const std::vector<std::string>& w) {
        if (w.empty()) return;
        const std::string& s = w[0];
        if (s == "v") {
            double p[3];
            numbers(line, w, 3, 7, p); // x y z, then an optional w or a colour
            out_.positions.emplace_back(p[0], p[1], p[2]);
            out_.positionLines.push_back(line);
        } else if (s == "vn") {
            numbers(line, w, 3, 3, nullptr);
            ++out_.normals;
        } else if (s == "vt") {
            numbers(line, w, 1, 3, nullptr);
            ++out_.uvs;
        } else if (s == "vp") {
            numbers(line, w, 1, 3, nullptr);
        } else if (s == "f") {
            if (w.size() < 4)
                fail(line, "a face needs at least 3 vertices, this one has " +
                               std::to_string(w.size() - 1));
            for (size_t i = 1; i < w.size(); ++i)
                reference(line, w[i], true);
            ++out_.faces;
        } else if (s == "l" || s == "p") {
            if (w.size() < (s == "l" ? 3u : 2u)) fail(line, "'" + s + "' has too few vertices");
            for (size_t i = 1; i < w.size(); ++i)
                reference(line, w[i], false);
        } else if (std::find_if(std::begin(kStatements), std::end(kStatements),
                                [&](const char* k) { return s == k; }) == std::end(kStatements)) {
            fail(line,
                 "'" + (s.size() > 40 ? s.substr(0, 40) + "..." : s) + "' is not an OBJ statement");
        }
    }

    const std::string& path_;
    ObjText& out_;
    long long maxIndex_[3] = {0, 0, 0};
    int maxIndexLine_[3] = {0, 0, 0};
};

std::string readFile(const std::string& path, const std::string& sceneFile, int sceneLine) {
    std::ifstream file(path, std::ios::binary);
    std::stringstream text;
    if (file) text << file.rdbuf();
    if (!file || file.bad())
        throw SceneError(sceneFile, sceneLine,
                         "cannot read OBJ file '" + path + "': " + std::strerror(errno));
    return text.str();
}

// tinyobjloader's reading of the checked text; it must agree with the checking pass on every
// element, or an index could read out of bounds: the file is refused rather than either trusted
// alone.
void parseChecked(const ObjText& obj, tinyobj::ObjReader& reader, const std::string& path,
                  const std::string& sceneFile, int sceneLine) {
    tinyobj::ObjReaderConfig cfg;
    cfg.triangulate = true;
    cfg.vertex_color = false;
    cfg.mtl_search_path = "";
    // Materials are ignored (shaders come from the scene): parse the geometry only.
    if (!reader.ParseFromString(obj.clean, "", cfg)) {
        std::string why = reader.Error();
        while (!why.empty() && (why.back() == '\n' || why.back() == '\r'))
            why.pop_back();
        throw SceneError(sceneFile, sceneLine, "cannot read OBJ file '" + path + "': " + why);
    }
    const tinyobj::attrib_t& a = reader.GetAttrib();
    if (a.vertices.size() != 3 * obj.positions.size() || a.normals.size() != 3 * obj.normals ||
        a.texcoords.size() != 2 * obj.uvs)
        throw SceneError(sceneFile, sceneLine,
                         "OBJ file '" + path +
                             "': tinyobjloader read a different number of "
                             "vertices, normals or texture coordinates than the file holds");
}

// The mesh, a vertex per distinct (position, normal, uv) triple of the OBJ, placed in the world
// relative to the camera.
class MeshBuilder {
  public:
    MeshBuilder(const ObjText& obj, const tinyobj::attrib_t& a, const glm::dmat4& objectToWorld,
                const glm::dvec3& origin, const std::string& path, const std::string& sceneFile,
                int sceneLine)
        : obj_(obj), a_(a), objectToWorld_(objectToWorld),
          normalXf_(glm::transpose(glm::inverse(glm::dmat3(objectToWorld)))),
          mirrors_(glm::determinant(glm::dmat3(objectToWorld)) < 0.0), origin_(origin), path_(path),
          sceneFile_(sceneFile), sceneLine_(sceneLine) {
        mesh_.name = path;
    }

    void addFace(const tinyobj::index_t* corners) {
        uvec3 tri;
        for (int k = 0; k < 3; ++k)
            tri[k] = vertex(corners[k]);
        // A mirroring transform turns the winding: keep the front faces the file's (as glTF's
        // loader and a mirroring instance do).
        if (mirrors_) std::swap(tri.y, tri.z);
        // Zero area as the renderer sees it: it normalises cross(e1, e2) in float, so |c|^2
        // must be a normal float (not 0, not a denormal that flush-to-zero turns into 0).
        vec3 e1 = mesh_.positions[tri.y] - mesh_.positions[tri.x];
        vec3 e2 = mesh_.positions[tri.z] - mesh_.positions[tri.x];
        vec3 c = glm::cross(e1, e2);
        const float c2 = glm::dot(c, c);
        if (std::isinf(c2) || std::isnan(c2))
            throw SceneError(sceneFile_, sceneLine_,
                             "OBJ file '" + path_ +
                                 "' has a triangle too large for float "
                                 "(its normal overflows): edges must stay below about 1e9");
        if (!(c2 >= std::numeric_limits<float>::min())) {
            ++mesh_.droppedTriangles;
            return;
        }
        mesh_.triangles.push_back(tri);
    }

    Mesh take() { return std::move(mesh_); }

  private:
    uint vertex(const tinyobj::index_t& ix) {
        const long long nv = (long long)obj_.positions.size(), nn = (long long)obj_.normals,
                        nt = (long long)obj_.uvs;
        if (ix.vertex_index < 0 || ix.vertex_index >= nv || ix.normal_index >= nn ||
            ix.texcoord_index >= nt)
            throw SceneError(sceneFile_, sceneLine_,
                             "OBJ file '" + path_ + "': a face index is out of range");
        const bool hasNormals = nn > 0, hasUvs = nt > 0;
        auto key = std::make_tuple(ix.vertex_index, hasNormals ? ix.normal_index : -1,
                                   hasUvs ? ix.texcoord_index : -1);
        auto [it, inserted] = remap_.try_emplace(key, uint(mesh_.positions.size()));
        if (!inserted) return it->second;
        // In double until here: the object's transform and the shift to the camera round once,
        // to float, at the end.
        const size_t vi = size_t(ix.vertex_index);
        const glm::dvec3 world =
            glm::dvec3(objectToWorld_ * glm::dvec4(obj_.positions[vi], 1.0)) - origin_;
        const std::string far =
            beyondReach(world, "vertex (after the object's transform, scene " + sceneFile_ + ":" +
                                   std::to_string(sceneLine_) + ")");
        if (!far.empty()) throw SceneError(path_, obj_.positionLines[vi], far);
        mesh_.positions.push_back(vec3(world));
        if (hasNormals) {
            glm::dvec3 n(0.0);
            const size_t ni = size_t(ix.normal_index);
            if (ix.normal_index >= 0)
                n = normalXf_ *
                    glm::dvec3(a_.normals[3 * ni], a_.normals[3 * ni + 1], a_.normals[3 * ni + 2]);
            const double len = glm::length(n);
            mesh_.normals.push_back(len > 0.0 && std::isfinite(len) ? vec3(n / len) : vec3(0.0f));
        }
        if (hasUvs) {
            vec2 uv(0.0f);
            const size_t ti = size_t(ix.texcoord_index);
            if (ix.texcoord_index >= 0) uv = vec2(a_.texcoords[2 * ti], a_.texcoords[2 * ti + 1]);
            mesh_.uvs.push_back(uv);
        }
        return it->second;
    }

    const ObjText& obj_;
    const tinyobj::attrib_t& a_;
    const glm::dmat4 objectToWorld_;
    const glm::dmat3 normalXf_;
    const bool mirrors_;
    const glm::dvec3 origin_;
    const std::string &path_, &sceneFile_;
    const int sceneLine_;
    Mesh mesh_;
    std::map<std::tuple<int, int, int>, uint> remap_;
};

} // namespace

Mesh loadObjMesh(const std::string& path, const glm::dmat4& objectToWorld, const glm::dvec3& origin,
                 const std::string& sceneFile, int sceneLine) {
    ObjText obj;
    ObjChecker(path, obj).check(readFile(path, sceneFile, sceneLine));
    if (obj.faces == 0)
        throw SceneError(sceneFile, sceneLine,
                         "OBJ file '" + path + "' has no face ('f' statement): nothing to render");
    tinyobj::ObjReader reader;
    parseChecked(obj, reader, path, sceneFile, sceneLine);
    MeshBuilder mesh(obj, reader.GetAttrib(), objectToWorld, origin, path, sceneFile, sceneLine);
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        const auto& idx = shape.mesh.indices;
        for (size_t f = 0; f + 2 < idx.size(); f += 3)
            mesh.addFace(&idx[f]);
    }
    return mesh.take();
}

} // namespace spw
