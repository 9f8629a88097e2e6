// What the BSDF suites share (header-only: CMake compiles tests/*/*_test.cpp and nothing else
// there):
//   * a chi-square goodness-of-fit test of a model's sampled directions against its pdf, after
//     pbrt-v3/v4's and Mitsuba's: the sphere is cut into cells, the expected count of each is N
//     times the pdf integrated over it by Gauss-Legendre quadrature, cells expecting fewer than
//     5 samples are pooled, and the p-value must stay above a 1% significance level with the
//     Šidák correction for the number of tests in the suite;
//   * the cells follow the lobes: each hemisphere (about ng) is parameterised by (theta, phi)
//     around its pole, and each coordinate is warped by a Cauchy-like map centred on the lobe
//     the model should produce there, with the lobe's width as scale. A GGX lobe 1e-3 wide then
//     spreads over many cells instead of falling into one, so the test keeps its power as
//     alpha -> 0 and at grazing angles. One more cell counts the samples the model absorbed.
//   * the same quadrature integrates the pdf (it must equal the share of samples not absorbed)
//     and f |cos| (it must equal the albedo the sample weights estimate).
#pragma once

#include "shared/bsdf.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace spw::test {

// ---- the model under test -----------------------------------------------------------------

struct BsdfUnderTest {
    ShaderParams sh{};
    vec3 albedo{1.0f};
    vec3 ng{0.0f, 0.0f, 1.0f};
    vec3 ns{0.0f, 0.0f, 1.0f};
    vec3 wo{0.0f, 0.0f, 1.0f};
};

inline ShaderParams shaderParams(uint model, float alpha = 0.0f, float ior = 1.5f) {
    ShaderParams sh{};
    sh.model = model;
    sh.colour = vec3(1.0f);
    sh.reflectance = 1.0f;
    sh.ior = ior;
    sh.alpha = alpha;
    return sh;
}

// A unit direction at polar angle theta (degrees) from n, azimuth phi (radians) in n's frame.
inline vec3 directionAround(vec3 n, double thetaDeg, double phi) {
    vec3 t, b;
    makeFrame(n, t, b);
    const double th = thetaDeg * M_PI / 180.0;
    return glm::normalize(float(std::sin(th) * std::cos(phi)) * t +
                          float(std::sin(th) * std::sin(phi)) * b + float(std::cos(th)) * n);
}

inline bool finiteNonNegative(vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && v.x >= 0 && v.y >= 0 &&
           v.z >= 0;
}

// Uniform numbers in [0, 1) on the renderer's 24-bit grid.
class Uniform {
  public:
    explicit Uniform(std::uint64_t seed) : rng_(seed) {}
    float next() { return float(rng_() >> 40) * (1.0f / 16777216.0f); }
    vec3 next3() {
        float a = next(), b = next(), c = next();
        return vec3(a, b, c);
    }

  private:
    std::mt19937_64 rng_;
};

// ---- statistics ---------------------------------------------------------------------------

// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes' series and continued fraction).
inline double upperIncompleteGamma(double a, double x) {
    if (x <= 0.0) return 1.0;
    const double gln = std::lgamma(a);
    if (x < a + 1.0) {
        double sum = 1.0 / a, del = sum, ap = a;
        for (int n = 0; n < 100000; ++n) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
        }
        return std::max(0.0, 1.0 - sum * std::exp(-x + a * std::log(x) - gln));
    }
    double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        const double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::fabs(d) < 1e-300) d = 1e-300;
        c = b + an / c;
        if (std::fabs(c) < 1e-300) c = 1e-300;
        d = 1.0 / d;
        const double del = d * c;
        h *= del;
        if (std::fabs(del - 1.0) < 1e-15) break;
    }
    return std::exp(-x + a * std::log(x) - gln) * h;
}

// P(chi^2_dof >= x).
inline double chiSquarePValue(double x, int dof) {
    return upperIncompleteGamma(0.5 * dof, 0.5 * x);
}

// The per-test threshold that keeps the whole suite of `tests` at `significance` (Šidák).
inline double sidakThreshold(double significance, int tests) {
    return 1.0 - std::pow(1.0 - significance, 1.0 / double(tests));
}

struct ChiSquareResult {
    double chi2 = 0, pValue = 0;
    int dof = 0, pooledCells = 0;
    std::string failure; // empty: the statistic could be computed
};

// pbrt's pooling: cells sorted by expected count; those expecting < minExpected are pooled
// (and further cells join the pool until it expects minExpected). A sample in a cell the pdf
// says is empty (beyond a 1e-5 share for rounding) fails outright.
inline ChiSquareResult chiSquare(const std::vector<double>& observed,
                                 const std::vector<double>& expected, double sampleCount,
                                 double minExpected = 5.0) {
    ChiSquareResult r;
    std::vector<size_t> order(observed.size());
    for (size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    double pooledObs = 0, pooledExp = 0;
    for (size_t i : order) {
        if (expected[i] <= 0.0) {
            if (observed[i] > sampleCount * 1e-5) {
                r.failure = "samples in a cell of expected count 0: " + std::to_string(observed[i]);
                return r;
            }
            pooledObs += observed[i];
        } else if (expected[i] < minExpected || (pooledExp > 0 && pooledExp < minExpected)) {
            pooledObs += observed[i];
            pooledExp += expected[i];
            ++r.pooledCells;
        } else {
            const double d = observed[i] - expected[i];
            r.chi2 += d * d / expected[i];
            ++r.dof;
        }
    }
    if (pooledExp > 0 || pooledObs > 0) {
        const double d = pooledObs - pooledExp;
        r.chi2 += pooledExp > 0 ? d * d / pooledExp : HUGE_VAL;
        ++r.dof;
    }
    r.dof -= 1;
    if (r.dof < 1) {
        r.failure = "too few degrees of freedom (" + std::to_string(r.dof) + ")";
        return r;
    }
    r.pValue = chiSquarePValue(r.chi2, r.dof);
    if (!std::isfinite(r.pValue)) r.failure = "p-value is not finite";
    return r;
}

// ---- the lobe-following cells of the sphere -------------------------------------------------

// x in [a, b] <-> s in [0, 1] through an arctangent centred at c with scale k: cells of equal
// width in s are narrow near c and wide far from it. k much larger than b - a is uniform.
struct Warp {
    double a, b, c, k, lo, hi;
    Warp(double a_, double b_, double c_, double k_) : a(a_), b(b_), c(c_), k(k_) {
        lo = std::atan((a - c) / k);
        hi = std::atan((b - c) / k);
    }
    double toUnit(double x) const {
        return std::clamp((std::atan((x - c) / k) - lo) / (hi - lo), 0.0, 1.0);
    }
    double fromUnit(double s) const { return c + k * std::tan(lo + s * (hi - lo)); }
    double jacobian(double s) const { // dx/ds
        const double x = fromUnit(s) - c;
        return (hi - lo) * (k * k + x * x) / k;
    }
};

// One hemisphere about +pole: polar angle theta in [0, pi/2] from the pole, azimuth phi in the
// pole's frame, both warped towards an expected lobe.
struct HemisphereGrid {
    vec3 pole, t, b;
    Warp theta{0, 1, 0, 1}, phi{0, 1, 0, 1};
    int nTheta, nPhi;

    // `lobe`: the direction the model's lobe centres on in this hemisphere (or zero: none);
    // `width`: its angular width in radians.
    HemisphereGrid(vec3 pole_, vec3 lobe, double width, int nTheta_, int nPhi_)
        : pole(pole_), nTheta(nTheta_), nPhi(nPhi_) {
        makeFrame(pole, t, b);
        double thetaC = 0, phiC = 0, kTheta = 1e3, kPhi = 1e3;
        if (glm::dot(lobe, lobe) > 0.0f && glm::dot(lobe, pole) > -1e-6f) {
            thetaC = std::acos(std::clamp(double(glm::dot(lobe, pole)), -1.0, 1.0));
            phiC = std::atan2(double(glm::dot(lobe, b)), double(glm::dot(lobe, t)));
            kTheta = width;
            kPhi = std::min(1e3, width / std::max(std::sin(thetaC), width));
        }
        theta = Warp(0.0, M_PI / 2, thetaC, kTheta);
        phi = Warp(phiC - M_PI, phiC + M_PI, phiC, kPhi);
    }

    vec3 direction(double th, double ph) const {
        return glm::normalize(float(std::sin(th) * std::cos(ph)) * t +
                              float(std::sin(th) * std::sin(ph)) * b + float(std::cos(th)) * pole);
    }
    // The cell of a direction in this hemisphere (angles in double: near the pole, acos of a
    // float cosine would be quantised to 3e-4 rad, coarser than a 1e-3 lobe).
    int cellOf(vec3 w) const {
        const glm::dvec3 dw(w), dp(pole), dt(t), db(b);
        const double th = std::atan2(glm::length(glm::cross(dw, dp)), glm::dot(dw, dp));
        double ph = std::atan2(glm::dot(dw, db), glm::dot(dw, dt));
        while (ph < phi.a)
            ph += 2 * M_PI;
        while (ph >= phi.b)
            ph -= 2 * M_PI;
        const int i = std::min(nTheta - 1, int(theta.toUnit(th) * nTheta));
        const int j = std::min(nPhi - 1, int(phi.toUnit(ph) * nPhi));
        return i * nPhi + j;
    }
    // Integral of f(direction) (a dvec2: two integrands at once) over each cell: 4 x 4
    // Gauss-Legendre points, subdivided adaptively (up to 7 times) where a quarter-split changes
    // the first component by more than 1e-3 relative or 1e-8 absolute, or where the support of f
    // ends inside the cell. A pdf may jump inside a cell (refraction at grazing incidence ends
    // where the microfacet normal reaches the horizon): only the sub-cells along the jump keep
    // splitting. An error of 1e-3 of a cell's E expected samples adds 1e-6 E to chi^2, and 1e-8
    // of probability is 0.002 of the 200000 samples a test draws: both far below the noise. (A
    // tighter relative bound only chases the float rounding of the pdf itself, which near a
    // 1e-3-wide lobe at grazing incidence reaches 1e-3.)
    template <class F> std::vector<glm::dvec2> integrate(const F& f) const {
        std::vector<glm::dvec2> out(size_t(nTheta * nPhi));
        for (int i = 0; i < nTheta; ++i)
            for (int j = 0; j < nPhi; ++j) {
                const double s0 = double(i) / nTheta, s1 = double(i + 1) / nTheta;
                const double u0 = double(j) / nPhi, u1 = double(j + 1) / nPhi;
                out[size_t(i * nPhi + j)] =
                    adaptive(f, s0, s1, u0, u1, gauss(f, s0, s1, u0, u1), 0);
            }
        return out;
    }

  private:
    template <class F>
    glm::dvec2 gauss(const F& f, double s0, double s1, double u0, double u1) const {
        static const double x4[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                     0.8611363115940526};
        static const double w4[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                     0.3478548451374538};
        glm::dvec2 sum(0.0);
        for (int a = 0; a < 4; ++a) {
            const double s = 0.5 * (s0 + s1) + 0.5 * (s1 - s0) * x4[a];
            const double th = theta.fromUnit(s);
            const double js = theta.jacobian(s) * std::sin(th);
            for (int c = 0; c < 4; ++c) {
                const double u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * x4[c];
                sum += (w4[a] * w4[c] * js * phi.jacobian(u)) * f(direction(th, phi.fromUnit(u)));
            }
        }
        return sum * (0.25 * (s1 - s0) * (u1 - u0));
    }
    template <class F>
    glm::dvec2 adaptive(const F& f, double s0, double s1, double u0, double u1, glm::dvec2 whole,
                        int depth) const {
        const double sm = 0.5 * (s0 + s1), um = 0.5 * (u0 + u1);
        const glm::dvec2 q[4] = {gauss(f, s0, sm, u0, um), gauss(f, sm, s1, u0, um),
                                 gauss(f, s0, sm, um, u1), gauss(f, sm, s1, um, u1)};
        const glm::dvec2 split = q[0] + q[1] + q[2] + q[3];
        if (depth >= 7) return split;
        // A support boundary close to an edge can hide from both Gauss rules (their outermost
        // nodes sit 7% and 3.5% inside): look for it on a lattice that reaches 0.1% of the edges.
        int zero = 0;
        for (double a : {0.001, 0.5, 0.999})
            for (double c : {0.001, 0.5, 0.999})
                zero += f(direction(theta.fromUnit(s0 + a * (s1 - s0)),
                                    phi.fromUnit(u0 + c * (u1 - u0))))
                            .x == 0.0;
        const bool mixedSupport = zero > 0 && zero < 9;
        if (!mixedSupport && std::fabs(split.x - whole.x) <= 1e-8 + 1e-3 * std::fabs(split.x))
            return split;
        return adaptive(f, s0, sm, u0, um, q[0], depth + 1) +
               adaptive(f, sm, s1, u0, um, q[1], depth + 1) +
               adaptive(f, s0, sm, um, u1, q[2], depth + 1) +
               adaptive(f, sm, s1, um, u1, q[3], depth + 1);
    }

  public:
};

// Where a model's lobes should be for wo: the lobe on each side of ng (zero vector: none).
struct ExpectedLobes {
    vec3 upper{0.0f}, lower{0.0f}; // on the +ng and -ng sides
    double width = 1.0;            // radians
};

struct SamplingReport {
    ChiSquareResult chi2;
    double pdfIntegral = 0;  // quadrature of the eval pdf over the sphere
    double successShare = 0; // samples not absorbed / all
    double fcosIntegral = 0; // quadrature of f |cos|: the albedo
    double meanWeight = 0;   // mean sample weight (0 for absorbed): the albedo, by sampling
    double meanWeightError = 0;
    size_t mismatches = 0; // samples whose eval disagrees with what sampling returned
    size_t samples = 0;
};

// How closely bsdfEval can reproduce what sampling returned for the same direction. Directions
// are float vectors (about 1e-7 of error each), and eval rebuilds the half vector from two of
// them: its error relative to the lobe's width alpha cos(theta_o) bounds the relative error of D.
inline double evalTolerance(const BsdfUnderTest& m) {
    if (m.sh.model == kModelLambert) return 2e-3;
    const double c = std::max(double(std::fabs(glm::dot(m.wo, m.ng))), 1e-3);
    double alpha = m.sh.alpha;
    if (m.sh.model == kModelCoatedMetallicRoughness || m.sh.model == kModelPrincipled)
        // the narrower of its two lobes
        alpha = std::min(alpha, std::max(double(m.sh.coatAlpha), double(kGltfMinAlpha)));
    return 2e-3 + 2e-6 / (std::max(alpha, 1e-9) * c);
}

// Samples `count` directions, bins them, integrates the pdf over the same cells, and checks each
// sample against bsdfEval (pdf and f |cos| = weight x pdf, to evalTolerance relative; f |cos|
// also to 1e-5 pdf absolute, for directions at the horizon where it is ~ cos(theta_i) ~ 0).
inline SamplingReport testSampling(const BsdfUnderTest& m, const ExpectedLobes& lobes, size_t count,
                                   std::uint64_t seed, int nTheta = 24, int nPhi = 48) {
    const double tolerance = evalTolerance(m);
    const HemisphereGrid upper(m.ng, lobes.upper, lobes.width, nTheta, nPhi);
    const HemisphereGrid lower(-m.ng, lobes.lower, lobes.width, nTheta, nPhi);
    const size_t half = size_t(nTheta * nPhi);
    std::vector<double> observed(2 * half + 1, 0.0);
    SamplingReport r;
    r.samples = count;
    Uniform u(seed);
    double sumW = 0, sumW2 = 0;
    for (size_t k = 0; k < count; ++k) {
        vec3 wi, weight;
        float pdf;
        bool specular;
        if (!bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, u.next3(), wi, weight, pdf, specular)) {
            observed[2 * half] += 1;
            continue;
        }
        const double w = (double(weight.x) + weight.y + weight.z) / 3.0;
        sumW += w;
        sumW2 += w * w;
        const bool up = glm::dot(wi, m.ng) > 0.0f;
        observed[up ? size_t(upper.cellOf(wi)) : half + size_t(lower.cellOf(wi))] += 1;
        float pdfEval;
        const vec3 fcos = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfEval);
        const bool pdfOk = std::fabs(pdfEval - pdf) <= tolerance * pdf;
        const vec3 expect = weight * pdf;
        const double slack = 1e-5 * pdf;
        const bool fOk = std::fabs(fcos.x - expect.x) <= tolerance * expect.x + slack &&
                         std::fabs(fcos.y - expect.y) <= tolerance * expect.y + slack &&
                         std::fabs(fcos.z - expect.z) <= tolerance * expect.z + slack;
        if (!pdfOk || !fOk || specular) {
            if (r.mismatches < 3)
                std::printf("    mismatch: wi (%g %g %g) sampled pdf %g eval pdf %g, weight*pdf %g "
                            "eval fcos %g\n",
                            wi.x, wi.y, wi.z, pdf, pdfEval, expect.x, fcos.x);
            ++r.mismatches;
        }
    }
    const double n = double(count);
    r.meanWeight = sumW / n;
    r.meanWeightError = std::sqrt(std::max(0.0, sumW2 / n - r.meanWeight * r.meanWeight) / n);
    r.successShare = 1.0 - observed[2 * half] / n;

    // pdf and f |cos| (channel average) of a direction, integrated together.
    auto pdfAndFcos = [&](vec3 wi) {
        float pdf;
        const vec3 f = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdf);
        return glm::dvec2(pdf, (double(f.x) + f.y + f.z) / 3.0);
    };
    std::vector<double> expected;
    for (const HemisphereGrid* g : {&upper, &lower})
        for (glm::dvec2 v : g->integrate(pdfAndFcos)) {
            expected.push_back(v.x * n);
            r.pdfIntegral += v.x;
            r.fcosIntegral += v.y;
        }
    expected.push_back(std::max(0.0, (1.0 - r.pdfIntegral) * n));
    r.chi2 = chiSquare(observed, expected, n);
    return r;
}

// The assertions every rough model's case makes; `tests`: the suite's number of chi-square tests.
inline void expectSamplingMatchesPdf(const SamplingReport& r, int tests, const std::string& what) {
    const double threshold = sidakThreshold(0.01, tests);
    std::printf("  %-44s chi2 %9.1f dof %4d p %.4f | int pdf %.6f, kept %.6f | int fcos %.6f, mean "
                "weight %.6f "
                "+- %.6f\n",
                what.c_str(), r.chi2.chi2, r.chi2.dof, r.chi2.pValue, r.pdfIntegral, r.successShare,
                r.fcosIntegral, r.meanWeight, r.meanWeightError);
    EXPECT_TRUE(r.chi2.failure.empty()) << what << ": " << r.chi2.failure;
    EXPECT_GE(r.chi2.pValue, threshold)
        << what << ": chi2 " << r.chi2.chi2 << " with " << r.chi2.dof << " dof";
    // The pdf integrates to the share of samples kept (1 but for samples the model absorbs).
    const double n = double(r.samples);
    const double p = std::clamp(r.successShare, 1e-9, 1.0);
    EXPECT_NEAR(r.pdfIntegral, r.successShare, 4.0 * std::sqrt(p * (1 - p) / n) + 2e-4) << what;
    EXPECT_LE(r.pdfIntegral, 1.0 + 1e-4) << what;
    // f |cos| integrates to the albedo that the sample weights estimate.
    EXPECT_NEAR(r.fcosIntegral, r.meanWeight, 4.0 * r.meanWeightError + 2e-4) << what;
    EXPECT_LE(double(r.mismatches), 1e-4 * n) << what << ": eval disagrees with sampling";
}

} // namespace spw::test
