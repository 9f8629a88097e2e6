// Every SIMD twin (host/simd/twins.h) against its scalar function in shaders/shared/, lane by
// lane and bit for bit, on random inputs that reach each branch (both signs, zeros, grazing
// angles, every sampler), in every instruction set this machine has: a change to either side of
// a twin fails here, at the function that drifted. And the tags: the scalar functions marked
// "SIMD twin" in shaders/shared/ are exactly the registry's.
#include "host/simd/simd_target.h"
#include "host/simd/twins.h"
#include "test_util.h"

#include "shared/conductor.h"
#include "shared/dielectric.h"
#include "shared/lambert.h"
#include "shared/metallic_roughness.h"
#include "shared/path.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <regex>
#include <set>
#include <string>

namespace spw::simd {
namespace {

constexpr size_t kLanes = kBlock; // a multiple of every vector width

// Random arguments: each float row a mix of ordinary values, zeros, negatives and near-zeros;
// unit vectors and [0, 1) numbers where the scalar function asks for them.
struct Inputs {
    TwinLanes lanes{};
    std::mt19937 rng;
    explicit Inputs(unsigned seed) : rng(seed) {}

    float any() {
        std::uniform_real_distribution<float> u(-4.0f, 4.0f);
        switch (rng() % 8) {
        case 0:
            return 0.0f;
        case 1:
            return std::ldexp(u(rng), -20);
        case 2:
            return std::ldexp(u(rng), 12);
        default:
            return u(rng);
        }
    }
    float unit() { return std::uniform_real_distribution<float>(0.0f, 1.0f)(rng); }
    vec3 direction() {
        std::normal_distribution<float> g;
        return normalize(vec3(g(rng), g(rng), g(rng)));
    }
    void fillAny() {
        for (Floats& row : lanes.f)
            for (float& x : row.v)
                x = any();
        for (Uints& row : lanes.u)
            for (std::uint32_t& x : row.v)
                x = std::uint32_t(rng());
    }
    void setUnit(int row) {
        for (float& x : lanes.f[row].v)
            x = unit();
    }
    void setDirection(int row) {
        for (size_t k = 0; k < kLanes; ++k)
            set3(row, k, direction());
    }
    // GGX widths: smooth (below kGgxSmoothAlpha), its edge, near-mirrors and rough.
    void setAlpha(int row) {
        for (float& a : lanes.f[row].v) {
            switch (rng() % 6) {
            case 0:
                a = rng() % 2 ? 0.0f : 0.5f * kGgxSmoothAlpha;
                break;
            case 1:
                a = kGgxSmoothAlpha;
                break;
            case 2:
                a = std::ldexp(unit(), -8);
                break;
            default:
                a = unit();
            }
        }
    }
    // glTF metalness: dielectric, metal and between.
    void setMetallic(int row) {
        for (float& m : lanes.f[row].v)
            m = rng() % 4 == 0 ? 0.0f : rng() % 3 == 0 ? 1.0f : unit();
    }
    // glTF's F90: 1 (no KHR_materials_specular), 0 and between.
    void setF90(int row) {
        for (float& x : lanes.f[row].v)
            x = rng() % 3 == 0 ? 1.0f : rng() % 4 == 0 ? 0.0f : unit();
    }
    // The dielectric part's F0 colour (rows row to row + 2) and F90 (row + 3): an ior's grey F0
    // with F90 1, as without KHR_materials_specular, or a coloured F0 times a weight.
    void setDielectricF0(int row) {
        for (size_t k = 0; k < kLanes; ++k) {
            const float f0 = 0.3f * unit();
            const bool plain = rng() % 2 == 0;
            const float w = plain ? 1.0f : unit();
            set3(row, k, plain ? vec3(f0) : w * min(vec3(unit(), unit(), unit()), vec3(1.0f)));
            lanes.f[row + 3].v[k] = w;
        }
    }
    void setRange(int row, float lo, float hi) {
        for (float& x : lanes.f[row].v)
            x = std::uniform_real_distribution<float>(lo, hi)(rng);
    }
    // A geometric normal, and a shading normal near it (or anywhere, now and then).
    void setNormals(int ngRow, int nsRow) {
        for (size_t k = 0; k < kLanes; ++k) {
            const vec3 ng = direction();
            set3(ngRow, k, ng);
            set3(nsRow, k, rng() % 4 ? normalize(ng + 0.3f * direction()) : direction());
        }
    }
    // A direction on the side of the normal in row ngRow, mostly.
    void setAbove(int row, int ngRow) {
        for (size_t k = 0; k < kLanes; ++k) {
            const vec3 w = direction();
            set3(row, k, rng() % 4 && dot(w, get3(ngRow, k)) < 0.0f ? -w : w);
        }
    }
    void set3(int row, size_t k, vec3 v) {
        lanes.f[row].v[k] = v.x;
        lanes.f[row + 1].v[k] = v.y;
        lanes.f[row + 2].v[k] = v.z;
    }
    vec3 get3(int row, size_t k) const {
        return vec3(lanes.f[row].v[k], lanes.f[row + 1].v[k], lanes.f[row + 2].v[k]);
    }
    float f(int row, size_t k) const { return lanes.f[row].v[k]; }
    std::uint32_t u(int row, size_t k) const { return lanes.u[row].v[k]; }
};

// The scalar side's results for lane k, as the twin writes them.
struct Expected {
    float f[8] = {};
    std::uint32_t u[4] = {};
    int floats = 0, uints = 0;
    void put(float x) { f[floats++] = x; }
    void put(vec3 v) { put(v.x), put(v.y), put(v.z); }
    void put(vec4 v) { put(v.x), put(v.y), put(v.z), put(v.w); }
    void putU(std::uint32_t x) { u[uints++] = x; }
    void putU(uvec4 v) { putU(v.x), putU(v.y), putU(v.z), putU(v.w); }
};

// A BSDF sample as its twin writes it: ok and specular as masks, the out-parameters zero where
// the sample failed (the scalar function leaves them unwritten then).
void putSample(Expected& e, bool ok, bool specular, vec3 wi, vec3 weight, float pdf) {
    e.putU(ok ? ~0u : 0u);
    e.putU(ok && specular ? ~0u : 0u);
    e.put(ok ? wi : vec3(0.0f));
    e.put(ok ? weight : vec3(0.0f));
    e.put(ok ? pdf : 0.0f);
}

// Each twin: how its arguments are drawn, and its scalar function on lane k.
struct ScalarSide {
    std::function<void(Inputs&)> draw;
    std::function<void(const Inputs&, size_t, Expected&)> eval;
};

const std::map<Twin, ScalarSide>& scalarSides() {
    static const std::map<Twin, ScalarSide> sides = {
        {Twin::maxComponent,
         {[](Inputs&) {},
          [](const Inputs& in, size_t k, Expected& e) { e.put(maxComponent(in.get3(0, k))); }}},
        {Twin::quantizePdf,
         {[](Inputs&) {},
          [](const Inputs& in, size_t k, Expected& e) { e.put(quantizePdf(in.f(0, k))); }}},
        {Twin::powerHeuristic,
         {[](Inputs&) {}, [](const Inputs& in, size_t k,
                             Expected& e) { e.put(powerHeuristic(in.f(0, k), in.f(1, k))); }}},
        {Twin::facingShadingNormal,
         {[](Inputs& in) { in.setDirection(0), in.setDirection(3), in.setDirection(6); },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(facingShadingNormal(in.get3(0, k), in.get3(3, k), in.get3(6, k)));
          }}},
        {Twin::sinQuarterPi,
         {[](Inputs& in) { in.setUnit(0); },
          [](const Inputs& in, size_t k, Expected& e) { e.put(sinQuarterPi(in.f(0, k))); }}},
        {Twin::cosQuarterPi,
         {[](Inputs& in) { in.setUnit(0); },
          [](const Inputs& in, size_t k, Expected& e) { e.put(cosQuarterPi(in.f(0, k))); }}},
        {Twin::sampleCosineHemisphere,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1);
              in.lanes.f[0].v[3] = in.lanes.f[1].v[3] = 0.5f; // the disk's centre
          },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(sampleCosineHemisphere(vec2(in.f(0, k), in.f(1, k))));
          }}},
        {Twin::toWorld,
         {[](Inputs& in) {
              in.setDirection(3);
              in.set3(3, 1, vec3(0.0f, 0.0f, -1.0f)); // makeFrame's singular pole
          },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(toWorld(in.get3(0, k), in.get3(3, k)));
          }}},
        {Twin::surfaceOffset,
         {[](Inputs& in) { in.setDirection(12); },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(surfaceOffset(in.get3(0, k), in.get3(3, k), in.get3(6, k), in.get3(9, k),
                                  in.get3(12, k)));
          }}},
        {Twin::offsetOrigin,
         {[](Inputs& in) { in.setDirection(3), in.setDirection(7); },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(offsetOrigin(in.get3(0, k), in.get3(3, k), in.f(6, k), in.get3(7, k)));
          }}},
        {Twin::shadowRayTmax,
         {[](Inputs&) {},
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(shadowRayTmax(in.f(0, k), in.f(1, k), in.f(2, k), in.f(3, k)));
          }}},
        {Twin::shadowLift,
         {[](Inputs& in) { in.setDirection(0), in.setDirection(4); },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(shadowLift(in.get3(0, k), in.f(3, k), in.get3(4, k), in.f(7, k)));
          }}},
        {Twin::emitterPoint,
         {[](Inputs& in) { in.setUnit(9), in.setUnit(10); },
          [](const Inputs& in, size_t k, Expected& e) {
              Emitter em{};
              em.p0 = in.get3(0, k), em.e1 = in.get3(3, k), em.e2 = in.get3(6, k);
              e.put(emitterPoint(em, vec2(in.f(9, k), in.f(10, k))));
          }}},
        {Twin::emitterCosine,
         {[](Inputs& in) {
              in.setDirection(0), in.setDirection(3);
              for (std::uint32_t& m : in.lanes.u[0].v)
                  m = (m & 1u) ? ~0u : 0u;
          },
          [](const Inputs& in, size_t k, Expected& e) {
              Emitter em{};
              em.normal = in.get3(0, k);
              em.twoSided = in.u(0, k) != 0u ? 1u : 0u;
              e.put(emitterCosine(em, in.get3(3, k)));
          }}},
        {Twin::emitterSolidAnglePdf,
         {[](Inputs&) {},
          [](const Inputs& in, size_t k, Expected& e) {
              Emitter em{};
              em.pickPdf = in.f(0, k), em.area = in.f(1, k);
              e.put(emitterSolidAnglePdf(em, in.f(2, k), in.f(3, k)));
          }}},
        {Twin::lambertEval,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1), in.setUnit(2);
              in.setDirection(3), in.setDirection(6), in.setDirection(9), in.setDirection(12);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              float pdf;
              e.put(lambertEval(in.get3(0, k), in.get3(3, k), in.get3(6, k), in.get3(9, k),
                                in.get3(12, k), pdf));
              e.put(pdf);
          }}},
        {Twin::ggxD,
         {[](Inputs& in) { in.setDirection(0), in.setAlpha(3); },
          [](const Inputs& in, size_t k, Expected& e) { e.put(ggxD(in.get3(0, k), in.f(3, k))); }}},
        {Twin::ggxA,
         {[](Inputs& in) { in.setDirection(0), in.setAlpha(3); },
          [](const Inputs& in, size_t k, Expected& e) { e.put(ggxA(in.get3(0, k), in.f(3, k))); }}},
        {Twin::ggxG2Denominator,
         {[](Inputs& in) { in.setDirection(0), in.setDirection(3), in.setAlpha(6); },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(ggxG2Denominator(in.get3(0, k), in.get3(3, k), in.f(6, k)));
          }}},
        {Twin::ggxSampleVisibleNormal,
         {[](Inputs& in) {
              in.setDirection(0), in.setAlpha(3), in.setUnit(4), in.setUnit(5);
              for (float& z : in.lanes.f[2].v)
                  z = std::fabs(z);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(
                  ggxSampleVisibleNormal(in.get3(0, k), in.f(3, k), vec2(in.f(4, k), in.f(5, k))));
          }}},
        {Twin::schlickFresnel,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1), in.setUnit(2), in.setRange(3, -0.5f, 1.5f);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(schlickFresnel(in.get3(0, k), in.f(3, k)));
          }}},
        {Twin::conductorEval,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1), in.setUnit(2), in.setAlpha(3), in.setNormals(4, 7);
              in.setAbove(10, 4), in.setAbove(13, 4);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              float pdf;
              e.put(conductorEval(in.get3(0, k), in.f(3, k), in.get3(4, k), in.get3(7, k),
                                  in.get3(10, k), in.get3(13, k), pdf));
              e.put(pdf);
          }}},
        {Twin::conductorSample,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1), in.setUnit(2), in.setAlpha(3), in.setNormals(4, 7);
              in.setAbove(10, 4), in.setUnit(13), in.setUnit(14);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              // Unwritten where the sample fails: putSample reads them only where it does not.
              vec3 wi(0.0f), weight(0.0f);
              float pdf = 0.0f;
              bool specular = false;
              const bool ok = conductorSample(
                  in.get3(0, k), in.f(3, k), in.get3(4, k), in.get3(7, k), in.get3(10, k),
                  vec2(in.f(13, k), in.f(14, k)), wi, weight, pdf, specular);
              putSample(e, ok, specular, wi, weight, pdf);
          }}},
        {Twin::fresnelDielectric,
         {[](Inputs& in) { in.setRange(0, -0.2f, 1.2f), in.setRange(1, 0.1f, 10.0f); },
          [](const Inputs& in, size_t k, Expected& e) {
              float cosT;
              e.put(fresnelDielectric(in.f(0, k), in.f(1, k), cosT));
              e.put(cosT);
          }}},
        {Twin::dielectricEval,
         {[](Inputs& in) {
              in.setRange(0, 1.01f, 10.0f), in.setAlpha(1), in.setNormals(2, 5);
              in.setAbove(8, 2), in.setDirection(11);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              float pdf;
              e.put(dielectricEval(in.f(0, k), in.f(1, k), in.get3(2, k), in.get3(5, k),
                                   in.get3(8, k), in.get3(11, k), pdf));
              e.put(pdf);
          }}},
        {Twin::dielectricSample,
         {[](Inputs& in) {
              in.setRange(0, 1.01f, 10.0f), in.setAlpha(1), in.setNormals(2, 5);
              in.setDirection(8), in.setUnit(11), in.setUnit(12), in.setUnit(13);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              // Unwritten where the sample fails: putSample reads them only where it does not.
              vec3 wi(0.0f), weight(0.0f);
              float pdf = 0.0f;
              bool specular = false;
              const bool ok = dielectricSample(
                  in.f(0, k), in.f(1, k), in.get3(2, k), in.get3(5, k), in.get3(8, k),
                  vec3(in.f(11, k), in.f(12, k), in.f(13, k)), wi, weight, pdf, specular);
              putSample(e, ok, specular, wi, weight, pdf);
          }}},
        {Twin::gltfFresnel,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1), in.setUnit(2), in.setF90(3);
              in.setRange(4, -0.2f, 1.2f);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(gltfFresnel(in.get3(0, k), in.f(3, k), in.f(4, k)));
          }}},
        {Twin::gltfSpecularProbability,
         {[](Inputs& in) {
              for (int row = 0; row < 6; ++row)
                  in.setUnit(row);
              in.setRange(6, 0.0f, 1.0f), in.setF90(7), in.setAlpha(8);
              in.lanes.f[3].v[0] = in.lanes.f[4].v[0] = in.lanes.f[5].v[0] = 0.0f; // no diffuse
          },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(gltfSpecularProbability(in.get3(0, k), in.f(7, k), in.get3(3, k), in.f(6, k),
                                            in.f(8, k)));
          }}},
        {Twin::gltfEval,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1), in.setUnit(2), in.setMetallic(3), in.setAlpha(4);
              in.setNormals(5, 8), in.setAbove(11, 5), in.setAbove(14, 5);
              in.setDielectricF0(17);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              float pdf;
              e.put(gltfEval(in.get3(0, k), in.f(3, k), in.f(4, k), in.get3(17, k), in.f(20, k),
                             in.get3(5, k), in.get3(8, k), in.get3(11, k), in.get3(14, k), pdf));
              e.put(pdf);
          }}},
        {Twin::gltfSample,
         {[](Inputs& in) {
              in.setUnit(0), in.setUnit(1), in.setUnit(2), in.setMetallic(3), in.setAlpha(4);
              in.setNormals(5, 8), in.setAbove(11, 5);
              in.setUnit(14), in.setUnit(15), in.setUnit(16), in.setDielectricF0(17);
          },
          [](const Inputs& in, size_t k, Expected& e) {
              // Unwritten where the sample fails: putSample reads them only where it does not.
              vec3 wi(0.0f), weight(0.0f);
              float pdf = 0.0f;
              bool specular = false;
              const bool ok = gltfSample(in.get3(0, k), in.f(3, k), in.f(4, k), in.get3(17, k),
                                         in.f(20, k), in.get3(5, k), in.get3(8, k), in.get3(11, k),
                                         vec3(in.f(14, k), in.f(15, k), in.f(16, k)), wi, weight,
                                         pdf, specular);
              putSample(e, ok, specular, wi, weight, pdf);
          }}},
        {Twin::pcg4d,
         {[](Inputs&) {},
          [](const Inputs& in, size_t k, Expected& e) {
              e.putU(pcg4d(uvec4(in.u(0, k), in.u(1, k), in.u(2, k), in.u(3, k))));
          }}},
        {Twin::laineKarrasPermutation,
         {[](Inputs&) {},
          [](const Inputs& in, size_t k, Expected& e) {
              e.putU(laineKarrasPermutation(in.u(0, k), in.u(1, k)));
          }}},
        {Twin::scrambledSobol4,
         {[](Inputs& in) { in.lanes.u[0].v[0] = 0u; },
          [](const Inputs& in, size_t k, Expected& e) {
              e.putU(scrambledSobol4(in.u(0, k),
                                     uvec4(in.u(1, k), in.u(2, k), in.u(3, k), in.u(4, k))));
          }}},
        {Twin::uintToUnit,
         {[](Inputs& in) { in.lanes.u[0].v[0] = ~0u, in.lanes.u[0].v[1] = 0u; },
          [](const Inputs& in, size_t k, Expected& e) { e.put(uintToUnit(in.u(0, k))); }}},
        {Twin::rand4,
         {[](Inputs& in) {
              for (std::uint32_t& b : in.lanes.u[2].v)
                  b %= 64u;
              in.lanes.uniform[0] = in.rng() % 2 ? kSamplerSobol : kSamplerIndependent;
              in.lanes.uniform[1] = std::uint32_t(in.rng());
              in.lanes.uniform[2] = kDimBsdf;
          },
          [](const Inputs& in, size_t k, Expected& e) {
              e.put(rand4(in.lanes.uniform[0], in.lanes.uniform[1], in.u(0, k), in.u(1, k),
                          in.u(2, k), in.lanes.uniform[2]));
          }}},
    };
    return sides;
}

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b));
}

// One twin on `rounds` blocks of random lanes; the first lane that differs is reported.
void expectTwinIsScalar(const TwinInfo& info, const ScalarSide& side, int rounds) {
    for (int round = 0; round < rounds; ++round) {
        Inputs in(1000u * unsigned(info.twin) + unsigned(round));
        in.fillAny();
        side.draw(in);
        TwinResults out{};
        runTwin(info.twin, in.lanes, kLanes, out);
        for (size_t k = 0; k < kLanes; ++k) {
            Expected e;
            side.eval(in, k, e);
            ASSERT_GT(e.floats + e.uints, 0);
            for (int r = 0; r < e.floats; ++r)
                ASSERT_TRUE(sameBits(out.f[r].v[k], e.f[r]))
                    << info.name << " (shared/" << info.header << "), round " << round << ", lane "
                    << k << ", result " << r << ": SIMD " << out.f[r].v[k] << ", scalar " << e.f[r];
            for (int r = 0; r < e.uints; ++r)
                ASSERT_EQ(out.u[r].v[k], e.u[r])
                    << info.name << " (shared/" << info.header << "), round " << round << ", lane "
                    << k << ", result " << r;
        }
    }
}

TEST(SimdTwins, EachTwinIsItsScalarFunctionLaneByLaneInEveryInstructionSet) {
    const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
    ASSERT_FALSE(targets.empty());
    for (int64_t target : targets) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(simdTarget());
        for (const TwinInfo& info : kTwins) {
            const auto side = scalarSides().find(info.twin);
            ASSERT_NE(side, scalarSides().end()) << info.name << ": no scalar side in this test";
            expectTwinIsScalar(info, side->second, 40);
        }
    }
    hwy::SetSupportedTargetsForTest(0);
}

// The tags "// SIMD twin: host/simd/simd_math-inl.h" (or simd_bsdf-inl.h) above SHARED_FN
// definitions in shaders/shared/, as (header, function) pairs; the file a tag names must name the
// function.
std::set<std::string> taggedFunctions() {
    std::set<std::string> out;
    static const std::regex fn("^SHARED_FN \\w+ (\\w+)\\(");
    static const std::regex tag("^// SIMD twin: (host/simd/simd_(math|bsdf)-inl\\.h)$");
    for (const char* header : {"sampling.h", "offset.h", "light_sample.h", "lights.h", "lambert.h",
                               "rng.h", "path.h", "bsdf.h", "ggx.h", "conductor.h", "dielectric.h",
                               "metallic_roughness.h", "cone.h", "types.h", "compat.h"}) {
        std::ifstream in(test::sourceDir() + "/shaders/shared/" + header);
        EXPECT_TRUE(in) << header;
        std::string line;
        bool tagged = false;
        std::string twinFile;
        while (std::getline(in, line)) {
            std::smatch m;
            if (tagged && std::regex_search(line, m, fn)) {
                out.insert(std::string(header) + " " + m[1].str());
                EXPECT_TRUE(std::regex_search(test::readFile(test::sourceDir() + "/" + twinFile),
                                              std::regex("\\b" + m[1].str() + "\\b")))
                    << header << ": " << m[1] << "'s tag names " << twinFile
                    << ", which has no twin of that name";
            } else if (tagged) {
                ADD_FAILURE() << header
                              << ": a SIMD twin tag not followed by a SHARED_FN: " << line;
            }
            tagged = std::regex_search(line, m, tag);
            if (tagged) twinFile = m[1];
        }
    }
    return out;
}

TEST(SimdTwins, TheTaggedScalarFunctionsAreTheRegistry) {
    std::set<std::string> registry;
    for (const TwinInfo& info : kTwins)
        registry.insert(std::string(info.header) + " " + info.name);
    EXPECT_EQ(taggedFunctions(), registry);
    EXPECT_EQ(scalarSides().size(), registry.size());
}

} // namespace
} // namespace spw::simd
