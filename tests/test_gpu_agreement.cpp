// GPU (float32 compute shader, default settings) against the CPU reference
// (double, converged settings) on every scene in scenes/ and in the course's
// scene files, and the fp64 shader (--precision fp64) on the hard cases. Runs on lavapipe in CI and is never skipped: no Vulkan device is
// a failure. On failure the GPU image, the reference and a difference image are
// written to build/test-artifacts/ and named in the message.
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpu/ComputeRenderer.h"
#include "image/ImageIO.h"
#include "metrics/ImageMetrics.h"
#include "reference/CpuRenderer.h"
#include "scene/Parser.h"
#include "gpu_test_context.h"
#include "vulkan/VulkanContext.h"

namespace fs = std::filesystem;

namespace {

// The thresholds of the Core issue, in 8-bit units.
constexpr double kMaxMeanError = 0.5;
constexpr double kMaxBadFraction = 0.001;
constexpr int kBadThreshold = 3;
// A pixel is ill-conditioned when its reference value moves by more than
// kBadThreshold as the primary rays move by this many pixels.
constexpr double kConditionShift = 1e-4;

struct Case {
    std::string path;
    int size = 128;
    int referenceDepth = 0;  // 0: kReferenceSettings
    // Issue 4's speckle rule holds for snell's own scenes; the course files'
    // speckles (chaotic multi-bounce pixels in becker-1n) are reported only.
    bool noSpeckles = true;
    snell::gpu::Precision precision = snell::gpu::Precision::Fp32;
};

void PrintTo(const Case& c, std::ostream* os) {
    *os << c.path << (c.precision == snell::gpu::Precision::Fp64 ? " (fp64)" : "");
}

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
        // Glass flake: ks + kt = 1.5, a ray tree that grows ~1.37x per level;
        // its reference stops at depth 20 (measured: depth 20 and 24 differ by
        // at most 3/255, and depth 64 is out of reach).
        if (name == "becker-SphereFlake2") c.referenceDepth = 20;
        c.noSpeckles = p.find("/course-scenes/") == std::string::npos;
        cases.push_back(c);
        if (p.find("/scenes/hard/") != std::string::npos) {
            c.precision = snell::gpu::Precision::Fp64;
            cases.push_back(c);
        }
    }
    return cases;
}

snell::vk::Context& context() { return snell::testing::gpuContext(); }

std::string testName(const testing::TestParamInfo<Case>& info) {
    std::string n = fs::path(info.param.path).parent_path().filename().string() + "_" +
                    fs::path(info.param.path).stem().string() +
                    (info.param.precision == snell::gpu::Precision::Fp64 ? "_fp64" : "");
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

bool movesFrom(const glm::dvec3& v, const snell::Image& exact, int x, int y) {
    for (int k = 0; k < 3; ++k)
        if (std::abs(int(snell::toByte(float(v[k]))) - int(snell::toByte(exact.pixel(x, y)[k]))) > kBadThreshold)
            return true;
    return false;
}

// Amplifying scenes (SPEC §4): a pixel whose reference still moves between 3/4
// of the reference depth and the full depth has not converged; its exact value
// is out of the reference's reach.
bool convergedAt(const snell::CpuRenderer& cpu, const snell::RenderRequest& reference, const snell::Image& exact,
                 int x, int y) {
    snell::RenderRequest shallower = reference;
    shallower.trace.maxDepth = reference.trace.maxDepth * 3 / 4;
    snell::RayCounts ignored;
    return !movesFrom(cpu.renderPixel(shallower, x, y, ignored), exact, x, y);
}

// Issue 4's rule: ill-conditioned when the value moves by more than 3/255 as
// the primary rays move by 1e-4 pixel, tried in eight directions.
bool illConditionedAt(const snell::CpuRenderer& cpu, const snell::RenderRequest& reference, const snell::Image& exact,
                      int x, int y) {
    const double h = std::sqrt(0.5);
    for (const glm::dvec2 shift : {glm::dvec2(1, 0), glm::dvec2(-1, 0), glm::dvec2(0, 1), glm::dvec2(0, -1),
                                   glm::dvec2(h, h), glm::dvec2(-h, h), glm::dvec2(h, -h), glm::dvec2(-h, -h)}) {
        snell::RenderRequest moved = reference;
        moved.camera.cornerDir += kConditionShift * (shift.x * moved.camera.pixelRight + shift.y * moved.camera.pixelDown);
        snell::RayCounts ignored;
        if (movesFrom(cpu.renderPixel(moved, x, y, ignored), exact, x, y)) return true;
    }
    return false;
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

    const std::uint32_t messagesBefore = context().validationMessages();
    snell::ComputeRenderer gpuRenderer(context(), scene, request.camera, c.precision);
    const snell::GpuRenderResult gpu = gpuRenderer.render(request, false);
    EXPECT_EQ(context().validationMessages(), messagesBefore) << "the Vulkan validation layer reported messages";

    snell::RenderRequest reference = request;
    reference.trace = snell::kReferenceSettings;
    if (c.referenceDepth) reference.trace.maxDepth = c.referenceDepth;
    const auto cpuStart = std::chrono::steady_clock::now();
    const snell::CpuRenderer cpu(scene);
    const snell::Image exact = cpu.render(reference);
    const double cpuMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cpuStart).count();

    const snell::ImageMetrics m = snell::compareImages(gpu.image, exact, kBadThreshold);
    // Pixels the reference itself shows to be out of reach are left out of the
    // bad-pixel and speckle counts, and counted.
    const bool amplifying = scene.anyAmplifying();
    std::vector<char> excluded(std::size_t(c.size) * c.size, 0);
    std::uint64_t illConditioned = 0, unconverged = 0;
    for (int y = 0; y < c.size; ++y) {
        for (int x = 0; x < c.size; ++x) {
            if (worstDifference(gpu.image, exact, x, y) <= kBadThreshold) continue;
            if (amplifying && !convergedAt(cpu, reference, exact, x, y)) {
                ++unconverged;
                excluded[std::size_t(y) * c.size + x] = 1;
            } else if (illConditionedAt(cpu, reference, exact, x, y)) {
                ++illConditioned;
                excluded[std::size_t(y) * c.size + x] = 1;
            }
        }
    }
    // Speckles: off by more than 8/255 with all eight neighbours within 2/255.
    std::uint64_t speckles = 0;
    for (int y = 1; y + 1 < c.size; ++y) {
        for (int x = 1; x + 1 < c.size; ++x) {
            if (excluded[std::size_t(y) * c.size + x] || worstDifference(gpu.image, exact, x, y) <= 8) continue;
            bool isolated = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if ((dx || dy) && worstDifference(gpu.image, exact, x + dx, y + dy) > 2) isolated = false;
            speckles += isolated;
        }
    }
    const double badFraction = double(m.badPixels - illConditioned - unconverged) / double(m.pixels);
    std::cout << "[ metrics ] " << fs::path(c.path).filename().string() << " " << m.json()
              << " ill_conditioned_left_out=" << illConditioned << " unconverged_left_out=" << unconverged
              << " speckles_counted=" << speckles << " gpu_ms=" << gpu.renderMs << " cpu_ms=" << cpuMs << "\n";

    const bool pass = m.nonFinite == 0 && (speckles == 0 || !c.noSpeckles) && m.meanAbsError <= kMaxMeanError && badFraction <= kMaxBadFraction;
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
    if (c.noSpeckles) {
        EXPECT_EQ(speckles, 0u) << "isolated pixels off by more than 8/255 (left out: " << m.speckles - speckles
                                << " ill-conditioned or unconverged)" << artifacts;
    }
    EXPECT_LE(m.meanAbsError, kMaxMeanError) << artifacts;
    EXPECT_LE(badFraction, kMaxBadFraction) << "bad pixels " << m.badPixels << ", ill-conditioned left out "
                                            << illConditioned << ", unconverged left out " << unconverged << artifacts;
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

namespace {

// The invocations' suspend-and-resume path (taken where the driver limits
// loops: old llvmpipe) gives the very image of one uninterrupted dispatch,
// however often it suspends: mid-tree with nested media (glass), deep
// amplifying trees (becker-1n), mid-way through the lights (256-lights), in
// the BVH (grid), with supersampling (showcase).
TEST(GpuResume, SuspendingNeverChangesTheImage) {
    for (const char* file : {SNELL_SOURCE_DIR "/scenes/glass.scn", SNELL_SHARED_DIR "/course-scenes/becker-1n.scn",
                             SNELL_SOURCE_DIR "/scenes/hard/256-lights.scn", SNELL_SOURCE_DIR "/scenes/grid.scn",
                             SNELL_SOURCE_DIR "/scenes/showcase.scn"}) {
        SCOPED_TRACE(file);
        const snell::Scene scene = snell::parseSceneFile(file);
        snell::RenderRequest request;
        request.width = request.height = 40;
        request.supersample = scene.supersample;
        request.camera = snell::Camera::fromSpec(40, scene.halfWidth);
        request.trace = snell::kDefaultSettings;
        snell::ComputeRenderer gpu(context(), scene, request.camera);
        const snell::GpuRenderResult whole = gpu.render(request, false);
        gpu.forceLoopBudget(48);
        const snell::GpuRenderResult resumed = gpu.render(request, false);
        EXPECT_GT(resumed.dispatches, 2 * whole.dispatches) << "the budget forced too few suspensions to test";
        EXPECT_EQ(resumed.image.rgb, whole.image.rgb);
    }
}

}  // namespace
