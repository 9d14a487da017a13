// GPU (float32 compute shader, default settings, its undecided pixels traced
// again by the CPU reference as `snell render` does) against the CPU
// reference (double, converged settings: the limit) on every scene in scenes/
// and in the course's scene files: in every pixel within the two renders'
// stated bounds (which cover rounding: render/Margins.h); a
// GPU's plan on the scenes where its paths differ, the fp64 shader
// (--precision fp64) on the hard cases, and the device's ray traversal
// (--traversal ray-query) on the hard cases and the BVH scenes; and the
// preview's inspection switches against the reference. Runs on lavapipe in
// CI and is never skipped: no Vulkan device is a failure. On failure the GPU
// image, the reference and a difference image are written to
// build/test-artifacts/ and named in the message. The kernel's other paths,
// each against its twin bit for bit: test_gpu_scheduling.cpp and
// test_gpu_kernels.cpp.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpu/ComputeRenderer.h"
#include "gpu/DriverProbe.h"
#include "image/ImageIO.h"
#include "metrics/ImageMetrics.h"
#include "reference/CpuRenderer.h"
#include "reference/CpuRetrace.h"
#include "scene/Parser.h"
#include "gpu_test_support.h"
#include "vulkan/VulkanContext.h"

namespace fs = std::filesystem;

namespace {

using snell::testing::context;

// The thresholds, in 8-bit units, against the limit reference (SPEC §4).
constexpr double kMaxMeanError = 0.25;
constexpr double kMaxBadFraction = 0.0005;
constexpr int kBadThreshold = 3;
// The reference certifies a pixel when its truncation bound (render/Truncation.h)
// is within half an 8-bit step: only there is the exact image known.
constexpr double kCertified = 0.5 / 255.0;
// At most this fraction of the pixels the reference certifies may state a
// GPU bound above an 8-bit step, widened over decisions the GPU left
// undecided (render/Margins.h): a bound that said "anything" everywhere
// would hold, and say nothing.
constexpr double kMaxWidened = 0.02;
constexpr double kWide = 1.0 / 255.0;

struct Case {
    std::string path;
    int size = 128;
    snell::gpu::Precision precision = snell::gpu::Precision::Fp32;
    snell::gpu::Traversal traversal = snell::gpu::Traversal::Walk;
    // Planned as on a GPU (RendererOptions::planAsGpu): its short frontiers
    // and thousands of workgroups sharing the tile, on lavapipe.
    bool gpuPlan = false;
};

const char* suffix(const Case& c) {
    return c.precision == snell::gpu::Precision::Fp64        ? "_fp64"
           : c.traversal == snell::gpu::Traversal::RayQuery ? "_ray_query"
           : c.gpuPlan                                       ? "_gpu_plan"
                                                              : "";
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.path << suffix(c); }

std::vector<Case> allCases() {
    std::vector<Case> cases;
    std::vector<std::string> paths;
    for (const auto& e : fs::recursive_directory_iterator(SNELL_SOURCE_DIR "/scenes"))
        if (e.path().extension() == ".scn") paths.push_back(e.path().string());
    for (const auto& e : fs::directory_iterator(SNELL_SHARED_DIR "/course-scenes"))
        if (e.path().extension() == ".scn") paths.push_back(e.path().string());
    std::sort(paths.begin(), paths.end());
    for (const std::string& p : paths) {
        Case c;
        c.path = p;
        const std::string name = fs::path(p).stem().string();
        cases.push_back(c);
        // A GPU's plan where its paths differ from lavapipe's: refraction
        // and BVH scenes (workgroups help with each other's shares), and a
        // scene with traps (frontiers; at 32 entries there, a GPU's plan
        // once lost the light of 87 pixels of glass-in-water-gap-0).
        if (p.find("/course-scenes/") != std::string::npos || name == "glass" || name == "glass-in-water-gap-0") {
            Case g = c;
            g.gpuPlan = true;
            cases.push_back(g);
        }
        const bool hard = p.find("/scenes/hard/") != std::string::npos;
        if (hard) {
            Case fp64 = c;
            fp64.precision = snell::gpu::Precision::Fp64;
            cases.push_back(fp64);
        }
        // The ray-query traversal where its float ray-box test is tested
        // hardest (the hard cases, searched through it from two spheres up)
        // and where it replaces the BVH walk.
        const std::size_t spheres = snell::parseSceneFile(p).spheres.size();
        if (spheres >= 2 && (hard || spheres > snell::gpu::kBvhThreshold)) {
            c.traversal = snell::gpu::Traversal::RayQuery;
            cases.push_back(c);
        }
    }
    return cases;
}

std::string testName(const testing::TestParamInfo<Case>& info) {
    std::string n = fs::path(info.param.path).parent_path().filename().string() + "_" +
                    fs::path(info.param.path).stem().string() + suffix(info.param);
    for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return n;
}

int worstDifference(const snell::Image& a, const snell::Image& b, int x, int y) {
    int worst = 0;
    for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(int(snell::toByte(a.pixel(x, y)[k])) - int(snell::toByte(b.pixel(x, y)[k]))));
    return worst;
}

class GpuAgreement : public testing::TestWithParam<Case> {};

TEST(GpuDevice, ExistsAndIsUsable) {
    // No Vulkan device is a failure, never a skip.
    ASSERT_NO_THROW(context());
    EXPECT_FALSE(context().deviceName().empty());
}

TEST_P(GpuAgreement, MatchesCpuReference) {
    const Case& c = GetParam();
    const snell::Scene scene = snell::parseSceneFile(c.path);
    snell::RenderRequest request;
    request.width = request.height = c.size;
    request.supersample = scene.supersample;
    request.camera = snell::Camera::fromSpec(c.size, scene.halfWidth);
    request.trace = snell::kDefaultSettings;
    std::vector<float> gpuBound, referenceBound, decisions;
    request.boundImage = &gpuBound;
    request.decisionImage = &decisions;
    request.retrace = snell::cpuRetrace(scene, request);

    const std::uint32_t messagesBefore = context().validationMessages();
    if (c.traversal == snell::gpu::Traversal::RayQuery && !context().rayQueriesEnabled()) {
        // A driver without ray queries (Mesa 22.3's lavapipe) refuses them, saying why.
        try {
            snell::ComputeRenderer refused(context(), scene, request.camera,
                                           {.precision = c.precision, .traversal = c.traversal});
            ADD_FAILURE() << "--traversal ray-query accepted on a device without ray queries";
        } catch (const snell::vk::VulkanError& e) {
            EXPECT_NE(std::string(e.what()).find("VK_KHR_"), std::string::npos) << e.what();
        }
        return;
    }
    if (c.precision == snell::gpu::Precision::Fp64 && !context().fp64Refusal().empty()) {
        // A driver the fp64 shader renders wrong on refuses it, saying why.
        EXPECT_THROW(snell::ComputeRenderer(context(), scene, request.camera,
                                            {.precision = c.precision, .traversal = c.traversal}),
                     snell::vk::VulkanError);
        return;
    }
    snell::ComputeRenderer gpuRenderer(context(), scene, request.camera,
                                       {.precision = c.precision, .traversal = c.traversal, .planAsGpu = c.gpuPlan});
    const bool bvh = scene.spheres.size() > snell::gpu::kBvhThreshold;
    EXPECT_STREQ(gpuRenderer.traversal(),
                 c.traversal == snell::gpu::Traversal::RayQuery ? "ray-query" : bvh ? "bvh" : "loop");
    const snell::GpuRenderResult gpu = gpuRenderer.render(request, false);
    EXPECT_EQ(context().validationMessages(), messagesBefore) << "the Vulkan validation layer reported messages";

    snell::RenderRequest reference = request;
    reference.trace = snell::kReferenceSettings;
    reference.decisionImage = nullptr;
    reference.retrace = nullptr;
    const snell::CpuRenderer cpu(scene);
    // The limit reference, rendered once a scene (its fp32 and fp64 cases share it).
    struct Limit {
        snell::Image image;
        std::vector<float> bound;
        double ms = 0.0;
    };
    static std::map<std::string, Limit> limits;
    if (!limits.count(c.path)) {
        Limit& l = limits[c.path];
        snell::RenderRequest r = reference;
        r.boundImage = &l.bound;
        const auto cpuStart = std::chrono::steady_clock::now();
        l.image = cpu.render(r);
        l.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cpuStart).count();
    }
    const snell::Image& exact = limits[c.path].image;
    referenceBound = limits[c.path].bound;
    const double cpuMs = limits[c.path].ms;

    const snell::ImageMetrics m = snell::compareImages(gpu.image, exact, kBadThreshold);
    // Every term of the ray sum is >= 0, so the exact colour lies between a
    // render's value and its value plus its truncation bound; where a decision
    // stayed undecided, within the widened bound either side (render/Margins.h).
    // So in every pixel the GPU and the reference differ by no more than their
    // two stated bounds (plus one 8-bit rounding step): no pixel is left out.
    // The scores (mean error, bad pixels) are over the pixels the reference
    // certifies, where the exact image is known.
    std::uint64_t certified = 0, bad = 0, boundViolations = 0, widened = 0, retraced = 0;
    double certifiedError = 0.0;
    for (int y = 0; y < c.size; ++y) {
        for (int x = 0; x < c.size; ++x) {
            const std::size_t i = std::size_t(y) * c.size + x;
            const int worst = worstDifference(gpu.image, exact, x, y);
            retraced += decisions[i] == 1.0f;
            if (worst > 255.0 * (gpuBound[i] + referenceBound[i]) + 1.0 && boundViolations++ < 5)
                ADD_FAILURE() << "pixel (" << x << ", " << y << ") off by " << worst << "/255, beyond the stated bounds "
                              << 255.0 * gpuBound[i] << "/255 (GPU) and " << 255.0 * referenceBound[i]
                              << "/255 (reference)";
            if (referenceBound[i] > kCertified) continue;
            ++certified;
            widened += decisions[i] == 2.0f && gpuBound[i] > kWide;
            for (int k = 0; k < 3; ++k)
                certifiedError += std::abs(int(snell::toByte(gpu.image.pixel(x, y)[k])) -
                                           int(snell::toByte(exact.pixel(x, y)[k])));
            bad += worst > kBadThreshold;
        }
    }
    const double meanError = certified ? certifiedError / (3.0 * double(certified)) : 0.0;
    const double badFraction = certified ? double(bad) / double(certified) : 0.0;
    const double widenedFraction = certified ? double(widened) / double(certified) : 0.0;
    std::cout << "[ metrics ] " << fs::path(c.path).filename().string() << " " << m.json()
              << " certified_mean_abs_error=" << meanError << " bad=" << bad << " of " << certified
              << " certified, bound_violations=" << boundViolations << " retraced=" << retraced
              << " widened=" << widened << " gpu_ms=" << gpu.renderMs << " cpu_ms=" << cpuMs << "\n";

    const bool pass = m.nonFinite == 0 && meanError <= kMaxMeanError && badFraction <= kMaxBadFraction &&
                      boundViolations == 0 && widenedFraction <= kMaxWidened;
    std::string artifacts;
    if (!pass) {
        fs::create_directories(SNELL_ARTIFACT_DIR);
        const std::string base = std::string(SNELL_ARTIFACT_DIR) + "/" + testName({GetParam(), 0});
        snell::writeImage(base + "-gpu.png", gpu.image);
        snell::writeImage(base + "-reference.png", exact);
        snell::writeImage(base + "-diff.png", snell::differenceImage(gpu.image, exact));
        artifacts = "\nimages: " + base + "-gpu.png, " + base + "-reference.png, " + base + "-diff.png";
    }
    EXPECT_EQ(m.nonFinite, 0u) << artifacts;
    EXPECT_LE(meanError, kMaxMeanError) << "over the " << certified << " pixels the reference certifies" << artifacts;
    EXPECT_LE(badFraction, kMaxBadFraction) << "bad pixels " << bad << " of " << certified << " certified" << artifacts;
    EXPECT_LE(widenedFraction, kMaxWidened) << widened << " pixels the reference certifies state bounds widened "
                                            << "over undecided decisions past 1/255" << artifacts;
    EXPECT_EQ(boundViolations, 0u) << artifacts;
}

INSTANTIATE_TEST_SUITE_P(Scenes, GpuAgreement, testing::ValuesIn(allCases()), testName);

}  // namespace

namespace {

// The preview's inspection switches and progressive samples, against the
// reference with the same settings.
TEST(GpuInspection, SwitchesAndProgressiveSamplesMatchReference) {
    const snell::Scene scene = snell::parseSceneFile(SNELL_SOURCE_DIR "/scenes/showcase.scn");
    snell::RenderRequest request;
    request.width = request.height = 64;
    request.supersample = 2;
    request.camera = snell::Camera::fromSpec(64, scene.halfWidth);
    snell::ComputeRenderer gpu(context(), scene, request.camera);
    const snell::CpuRenderer cpu(scene);
    const snell::Image full = gpu.render(request, false).image;
    for (int k = 0; k < 3; ++k) {
        snell::RenderRequest r = request;
        r.trace = snell::kDefaultSettings;
        (k == 0 ? r.trace.shadows : k == 1 ? r.trace.reflection : r.trace.refraction) = false;
        const snell::Image g = gpu.render(r, false).image;
        r.trace.minWeight = snell::kReferenceSettings.minWeight;
        const snell::ImageMetrics m = snell::compareImages(g, cpu.render(r), kBadThreshold);
        EXPECT_LE(m.meanAbsError, kMaxMeanError) << "switch " << k;
        EXPECT_LE(m.badFraction, kMaxBadFraction) << "switch " << k;
        EXPECT_GT(snell::compareImages(g, full, kBadThreshold).meanAbsError, 0.5) << "switch " << k << " changed nothing";
    }
    // Four one-sample renders average to the 2×2 supersampled image.
    snell::Image mean(64, 64);
    for (int sample = 0; sample < 4; ++sample) {
        snell::RenderRequest r = request;
        r.firstSample = sample;
        r.sampleCount = 1;
        const snell::Image one = gpu.render(r, false).image;
        for (std::size_t i = 0; i < mean.rgb.size(); ++i) mean.rgb[i] += 0.25f * one.rgb[i];
    }
    const snell::ImageMetrics m = snell::compareImages(mean, full, kBadThreshold);
    EXPECT_LE(m.maxError, 1);
}

}  // namespace
