// The scene model's few functions: what its types answer about themselves, and the rules that
// every loader applies to what a file says (how far from the camera a scene may reach, how a
// number is written in a message).
#include "host/scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace spw {

std::string formatNumber(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    std::string s = std::to_string(v);
    if (std::fabs(v) >= 1e7 || (v != 0 && std::fabs(v) < 1e-4)) {
        // 1e+20 -> 1e20, 1e-05 -> 1e-5: as the format's ranges are written.
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", v);
        std::string g = buf;
        const size_t e = g.find('e');
        if (e == std::string::npos) return g;
        std::string mant = g.substr(0, e), exp = g.substr(e + 1);
        const bool neg = exp[0] == '-';
        exp.erase(0, exp.find_first_not_of("+-0"));
        return mant + "e" + (neg ? "-" : "") + (exp.empty() ? "0" : exp);
    }
    s.erase(s.find_last_not_of('0') + 1);
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
}

std::string beyondReach(const glm::dvec3& p, const std::string& what) {
    const double far = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    if (far <= kMaxDistance) return "";
    return what + " lies " + formatNumber(far) +
           " units from the camera; Spillway renders within " + formatNumber(kMaxDistance) +
           " units of it";
}

float Camera::tanHalfFovX() const {
    if (fovDegrees) return std::tan(glm::radians(*fovDegrees) * 0.5f);
    return 0.5f * filmWidth / focalLength;
}

const char* samplerName(SamplerType s) {
    switch (s) {
    case SamplerType::Independent:
        return "Independent";
    case SamplerType::Grid:
        return "Grid";
    case SamplerType::Stratified:
        return "Stratified";
    case SamplerType::Sobol:
        return "Sobol";
    }
    return "?";
}

std::optional<SamplerType> parseSampler(const std::string& name) {
    for (SamplerType s :
         {SamplerType::Independent, SamplerType::Grid, SamplerType::Stratified, SamplerType::Sobol})
        if (name == samplerName(s)) return s;
    return std::nullopt;
}

bool Scene::usesTextures() const {
    for (const Shader& s : shaders)
        if (s.texture >= 0) return true;
    return false;
}

} // namespace spw
