// The scene loader's YAML reading: typed, range-checked values whose errors name the scene file
// and the node's line (SceneError), and the transforms every placed element reads. Used by the
// loader's parts (scene_loader.cpp, light_loader.cpp) only.
#pragma once

#include "host/scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace spw::scene_file {

class Reader {
  public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const YAML::Node& at, const std::string& message) const {
        throw SceneError(file_, at.Mark().line + 1, message);
    }
    [[noreturn]] void fail(int line, const std::string& message) const {
        throw SceneError(file_, line, message);
    }

    // A map node whose keys are all in `allowed`; returns (key, value) pairs in file order.
    void checkKeys(const YAML::Node& map, const std::string& what,
                   const std::vector<std::string>& allowed) const {
        if (!map.IsMap()) fail(map, what + " must be a map of keys to values");
        for (auto it = map.begin(); it != map.end(); ++it) {
            std::string key = it->first.as<std::string>();
            bool known = false;
            for (const std::string& a : allowed)
                known = known || key == a;
            if (!known) fail(it->first, "unknown key '" + key + "' in " + what);
        }
    }

    std::string string(const YAML::Node& n, const std::string& what) const {
        if (!n.IsScalar()) fail(n, what + " must be a string");
        return n.as<std::string>();
    }

    double number(const YAML::Node& n, const std::string& what) const {
        if (!n.IsScalar()) fail(n, what + " must be a number");
        double v;
        if (!YAML::convert<double>::decode(n, v))
            fail(n, what + " must be a number, not '" + n.Scalar() + "'");
        if (!std::isfinite(v)) fail(n, what + " must be finite");
        return v;
    }

    double number(const YAML::Node& n, const std::string& what, double lo, double hi) const {
        double v = number(n, what);
        if (v < lo || v > hi)
            fail(n, what + " must be in [" + fmt(lo) + ", " + fmt(hi) + "], not " + fmt(v));
        return v;
    }

    long long integer(const YAML::Node& n, const std::string& what, long long lo,
                      long long hi) const {
        if (!n.IsScalar()) fail(n, what + " must be an integer");
        long long v;
        if (!YAML::convert<long long>::decode(n, v))
            fail(n, what + " must be an integer, not '" + n.Scalar() + "'");
        if (v < lo || v > hi)
            fail(n, what + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                        "], not " + std::to_string(v));
        return v;
    }

    bool boolean(const YAML::Node& n, const std::string& what) const {
        bool v;
        if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
            fail(n, what + " must be true or false");
        return v;
    }

    template <int N>
    glm::vec<N, float> vec(const YAML::Node& n, const std::string& what, double lo = -HUGE_VAL,
                           double hi = HUGE_VAL) const {
        return glm::vec<N, float>(dvec<N>(n, what, lo, hi));
    }

    template <int N>
    glm::vec<N, double> dvec(const YAML::Node& n, const std::string& what, double lo = -HUGE_VAL,
                             double hi = HUGE_VAL) const {
        if (!n.IsSequence() || n.size() != N)
            fail(n, what + " must be a list of " + std::to_string(N) + " numbers");
        glm::vec<N, double> v;
        for (int i = 0; i < N; ++i)
            v[i] = number(n[i], what, lo, hi);
        return v;
    }

    const std::string& file() const { return file_; }

    static std::string fmt(double v) { return formatNumber(v); }

  private:
    std::string file_;
};

// R = Rz * Ry * Rx, degrees.
inline glm::dmat4 rotationXYZ(glm::dvec3 degrees) {
    glm::dmat4 r(1.0);
    r = glm::rotate(r, glm::radians(degrees.z), glm::dvec3(0, 0, 1));
    r = glm::rotate(r, glm::radians(degrees.y), glm::dvec3(0, 1, 0));
    r = glm::rotate(r, glm::radians(degrees.x), glm::dvec3(1, 0, 0));
    return r;
}

// translation * rotation * scale, reading whichever of the three keys are present. In double:
// the scene is moved to the camera before anything is rounded to float.
inline glm::dmat4 readTransform(const Reader& rd, const YAML::Node& n, const std::string& what,
                                bool scale3) {
    glm::dmat4 m(1.0);
    if (n["translation"])
        m = glm::translate(m, rd.dvec<3>(n["translation"], what + " translation"));
    if (n["rotation"]) m = m * rotationXYZ(rd.dvec<3>(n["rotation"], what + " rotation"));
    if (scale3 && n["scale"]) {
        const YAML::Node& s = n["scale"];
        glm::dvec3 sc = s.IsScalar() ? glm::dvec3(rd.number(s, what + " scale"))
                                     : rd.dvec<3>(s, what + " scale");
        if (sc.x == 0 || sc.y == 0 || sc.z == 0) rd.fail(s, what + " scale must not be zero");
        m = glm::scale(m, sc);
    }
    return m;
}

inline void checkDistance(const Reader& rd, const YAML::Node& at, const glm::dvec3& p,
                          const std::string& what) {
    const std::string why = beyondReach(p, what);
    if (!why.empty()) rd.fail(at, why);
}

} // namespace spw::scene_file
