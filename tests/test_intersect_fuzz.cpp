// The intersector the shader runs (shaders/intersect.glsl, through the test
// kernel intersect_kernel.comp), in float32 and in fp64 (float pairs in, as
// the renderer stores them), against the double one the reference uses
// (host/reference/Intersect.h), on random spheres, ellipsoids and rays at
// scales from 1e-4 to 1e6: hit/miss disagreement and relative t error.
// The bounds are documented in docs/accuracy.md ("Numerical robustness").
#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gpu_test_context.h"
#include "gpu/GpuScene.h"
#include "intersect_kernel_comp_spv.h"
#include "intersect_kernel_fp64_comp_spv.h"
#include "kernel_layout.h"
#include "reference/Intersect.h"
#include "scene/Transform.h"
#include "vulkan/ComputeKernel.h"

namespace {

using glm::dvec3;

struct Truth {
    double t;  // double-precision result (kNoHit for a miss)
    bool onSurface;
};

// v, w as the float pair hi + lo (the renderer's storage).
void split(const dvec3& v, double w, glm::vec4& hi, glm::vec4& lo) {
    for (int k = 0; k < 3; ++k) snell::gpu::splitDouble(v[k], hi[k], lo[k]);
    snell::gpu::splitDouble(w, hi.w, lo.w);
}

dvec3 randomUnit(std::mt19937_64& rng) {
    std::normal_distribution<double> n;
    return glm::normalize(dvec3(n(rng), n(rng), n(rng)));
}

double logUniform(std::mt19937_64& rng, double lo, double hi) {
    return std::pow(10.0, std::uniform_real_distribution<double>(lo, hi)(rng));
}

// One random case: a sphere or ellipsoid at scale `scale` and a ray that may
// start on its surface (entering or leaving) or elsewhere, aimed near it.
void makeCase(std::mt19937_64& rng, snell::gpu::IntersectCase& c, Truth& truth) {
    const double scale = logUniform(rng, -4, 6);
    const bool ellipsoid = std::uniform_int_distribution<int>(0, 2)(rng) == 0;
    const dvec3 centre = randomUnit(rng) * scale * logUniform(rng, -0.5, 1.0);
    glm::dmat4 worldFromObject(1.0);
    double radius = scale * logUniform(rng, -1.0, 0.5);
    if (ellipsoid) {
        snell::Transform t;
        t.translate(centre);
        t.rotate(std::uniform_real_distribution<double>(0, 360)(rng), randomUnit(rng));
        t.scale(dvec3(radius * logUniform(rng, -2, 0), radius * logUniform(rng, -2, 0), radius));
        worldFromObject = t.worldFromObject();
        const glm::dmat4 objectFromWorld = t.objectFromWorld();
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row)
                snell::gpu::splitDouble(objectFromWorld[col][row], c.objectFromWorld[col][row],
                                        c.objectFromWorldLow[col][row]);
        c.kind = SNELL_CASE_ELLIPSOID;
    } else {
        const double distance = glm::length(centre);
        const dvec3 n0 = distance > 0 ? -centre / distance : dvec3(0, 0, 1);
        split(centre + radius * n0, radius, c.anchorRadius, c.anchorRadiusLow);
        split(n0, 0.0, c.normal, c.normalLow);
        c.kind = SNELL_CASE_TRUE_SPHERE;
    }
    // A point on the surface, and one near the sphere to aim at.
    const dvec3 u = randomUnit(rng);
    const dvec3 surface = ellipsoid ? dvec3(worldFromObject * glm::dvec4(u, 1.0)) : centre + radius * u;
    const dvec3 target = ellipsoid ? dvec3(worldFromObject * glm::dvec4(1.3 * randomUnit(rng) *
                                                                             std::cbrt(std::uniform_real_distribution<double>(0, 1)(rng)), 1.0))
                                   : centre + 1.3 * radius * randomUnit(rng);
    snell::StartsOn mode = snell::StartsOn::Elsewhere;
    dvec3 origin, dir;
    if (std::uniform_int_distribution<int>(0, 3)(rng) == 0) {
        origin = surface;
        dir = randomUnit(rng);
        // The renderer decides entering/leaving from the shading geometry; here
        // from the exact normal.
        const dvec3 normal = ellipsoid ? glm::normalize(glm::transpose(glm::dmat3(glm::inverse(worldFromObject))) * u) : u;
        mode = glm::dot(dir, normal) < 0 ? snell::StartsOn::Entering : snell::StartsOn::Leaving;
    } else {
        origin = randomUnit(rng) * scale * logUniform(rng, -1.0, 0.5);
        dir = glm::normalize(target - origin);
    }
    split(origin, 0.0, c.origin, c.originLow);
    split(dir, 0.0, c.direction, c.directionLow);
    c.mode = mode == snell::StartsOn::Elsewhere ? 0u : mode == snell::StartsOn::Leaving ? 1u : 2u;
    truth.onSurface = mode != snell::StartsOn::Elsewhere;
    if (ellipsoid) {
        const glm::dmat4 objectFromWorld = glm::inverse(worldFromObject);
        truth.t = snell::intersectUnitSphere(dvec3(objectFromWorld * glm::dvec4(origin, 1.0)),
                                             glm::dmat3(objectFromWorld) * dir, mode);
    } else {
        truth.t = snell::intersectSphere(centre, radius, {origin, dir}, mode);
    }
}

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, std::size_t(p * (v.size() - 1)))];
}

struct Bounds {
    const char* name;
    const std::uint32_t* spirv;
    std::size_t spirvBytes;
    // Documented bounds (docs/accuracy.md): disagreements are grazing rays whose answer
    // the precision cannot resolve.
    double disagreement, p50, p99, surfaceDisagreement, surfaceP99;
};

void PrintTo(const Bounds& b, std::ostream* os) { *os << b.name; }

class IntersectFuzz : public testing::TestWithParam<Bounds> {};

TEST_P(IntersectFuzz, AgainstDouble) {
    const Bounds& bounds = GetParam();
    snell::vk::Context& context = snell::testing::gpuContext();
    if (bounds.spirv == snell_intersect_kernel_fp64_comp_spv) {
        ASSERT_TRUE(context.float64Supported()) << context.deviceName() << " has no shaderFloat64";
    }
    constexpr std::uint32_t kCases = 200000;
    std::mt19937_64 rng(20261122);
    std::vector<snell::gpu::IntersectCase> cases(kCases);
    std::vector<Truth> truth(kCases);
    for (std::uint32_t i = 0; i < kCases; ++i) {
        cases[i] = {};
        makeCase(rng, cases[i], truth[i]);
    }
    cases[0].count = kCases;

    snell::vk::Buffer input = context.createBufferWithData(cases.data(), cases.size() * sizeof cases[0],
                                                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    snell::vk::Buffer output = context.createBuffer(kCases * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                                    snell::vk::Context::Memory::HostCached);
    {
        snell::vk::ComputeKernel kernel(context, bounds.spirv, bounds.spirvBytes, 2);
        kernel.run({&input, &output}, nullptr, (kCases + SNELL_KERNEL_GROUP_SIZE - 1) / SNELL_KERNEL_GROUP_SIZE);
    }
    std::vector<glm::vec4> results(kCases);
    std::memcpy(results.data(), output.mapped, kCases * sizeof(glm::vec4));
    context.destroy(input);
    context.destroy(output);

    std::uint64_t disagree = 0, hits = 0, surfaceCases = 0, surfaceDisagree = 0;
    std::vector<double> relativeError, surfaceError;
    for (std::uint32_t i = 0; i < kCases; ++i) {
        const bool hit32 = results[i].x < 1e38f;  // the shader's result, whatever its precision
        const double t = double(results[i].x) + double(results[i].y);
        const bool hit64 = truth[i].t != snell::kNoHit;
        if (truth[i].onSurface) {
            ++surfaceCases;
            if (hit32 != hit64) ++surfaceDisagree;
            else if (hit64) surfaceError.push_back(std::abs(t - truth[i].t) / truth[i].t);
            continue;
        }
        if (hit32 != hit64) {
            ++disagree;
            continue;
        }
        if (!hit64) continue;
        ++hits;
        relativeError.push_back(std::abs(t - truth[i].t) / truth[i].t);
    }
    const double elsewhere = double(kCases - surfaceCases);
    const double disagreement = disagree / elsewhere;
    const double p50 = percentile(relativeError, 0.5), p99 = percentile(relativeError, 0.99),
                 p999 = percentile(relativeError, 0.999);
    const double s50 = percentile(surfaceError, 0.5), s99 = percentile(surfaceError, 0.99);
    std::cout << "[ fuzz    ] " << bounds.name << ": cases " << kCases << ", rays from elsewhere " << elsewhere << " (hits " << hits
              << "), hit/miss disagreement " << disagreement << "; relative t error p50 " << p50 << ", p99 " << p99
              << ", p99.9 " << p999 << "; rays from the surface " << surfaceCases << ", disagreement "
              << double(surfaceDisagree) / surfaceCases << ", chord error p50 " << s50 << ", p99 " << s99 << "\n";
    EXPECT_LE(disagreement, bounds.disagreement);
    EXPECT_LE(p50, bounds.p50);
    EXPECT_LE(p99, bounds.p99);
    EXPECT_LE(double(surfaceDisagree) / surfaceCases, bounds.surfaceDisagreement);
    EXPECT_LE(s99, bounds.surfaceP99);
}

INSTANTIATE_TEST_SUITE_P(
    Precisions, IntersectFuzz,
    testing::Values(Bounds{"fp32", snell_intersect_kernel_comp_spv, sizeof snell_intersect_kernel_comp_spv, 1e-3,
                           1e-6, 1e-5, 1e-3, 1e-3},
                    Bounds{"fp64", snell_intersect_kernel_fp64_comp_spv, sizeof snell_intersect_kernel_fp64_comp_spv,
                           1e-4, 1e-14, 1e-13, 1e-4, 1e-10}),
    [](const testing::TestParamInfo<Bounds>& info) { return std::string(info.param.name); });

}  // namespace
