// GPU (float32 compute shader, default settings) against the CPU reference
// (double, converged settings: the limit) on every scene in scenes/ and in the
// course's scene files, within the tolerance and the reference's bounds; a
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
// At most this fraction of a scene's pixels may be left out as ill-conditioned.
constexpr double kMaxIllConditioned = 0.01;
// A pixel is ill-conditioned when its reference value moves by more than
// kBadThreshold as the primary rays move by this many pixels.
constexpr double kConditionShift = 1e-4;

struct Case {
    std::string path;
    int size = 128;
    // Issue 4's speckle rule holds for snell's own scenes; the course files'
    // speckles (chaotic multi-bounce pixels in becker-1n) are reported only.
    bool noSpeckles = true;
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
        c.noSpeckles = p.find("/course-scenes/") == std::string::npos;
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

// How far (in 8-bit steps) the GPU's pixel lies below the reference's value,
// a lower bound of the exact colour, in its worst channel.
int belowLowerBound(const snell::Image& gpu, const snell::Image& reference, int x, int y) {
    int worst = 0;
    for (int k = 0; k < 3; ++k)
        worst = std::max(worst, int(snell::toByte(reference.pixel(x, y)[k])) - int(snell::toByte(gpu.pixel(x, y)[k])));
    return worst;
}

bool movesFrom(const glm::dvec3& v, const snell::Image& exact, int x, int y) {
    for (int k = 0; k < 3; ++k)
        if (std::abs(int(snell::toByte(float(v[k]))) - int(snell::toByte(exact.pixel(x, y)[k]))) > kBadThreshold)
            return true;
    return false;
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
        if (movesFrom(cpu.renderPixel(moved, x, y, ignored).colour, exact, x, y)) return true;
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
    std::vector<float> gpuBound, referenceBound;
    request.boundImage = &gpuBound;

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
    // Every term of the ray sum is >= 0, so the reference's value is a lower
    // bound of the exact colour in every pixel, and its value plus its stated
    // bound an upper bound (render/Truncation.h): a GPU pixel outside them by
    // more than the bad-pixel threshold is wrong, certified or not. Pixels the
    // reference cannot certify (light of an amplifying material that need not
    // decay, a tree over its budget) and that lie within them are left out, as
    // are pixels the reference shows to be ill-conditioned (at most
    // kMaxIllConditioned of them); both are counted. A pixel off by more than
    // the threshold must, in fp64, lie within the GPU's and the reference's
    // stated bounds (plus one 8-bit rounding step).
    std::vector<char> excluded(std::size_t(c.size) * c.size, 0);
    std::uint64_t illConditioned = 0, uncertified = 0, bad = 0, provenWrong = 0, boundViolations = 0;
    double comparedError = 0.0;
    for (int y = 0; y < c.size; ++y) {
        for (int x = 0; x < c.size; ++x) {
            const std::size_t i = std::size_t(y) * c.size + x;
            const int worst = worstDifference(gpu.image, exact, x, y);
            if (referenceBound[i] > kCertified) {
                const int below = belowLowerBound(gpu.image, exact, x, y);
                const int above = worst - int(std::ceil(255.0 * referenceBound[i]));
                if (std::max(below, above) <= kBadThreshold) {
                    ++uncertified;
                    excluded[i] = 1;
                    continue;
                }
            }
            for (int k = 0; k < 3; ++k)
                comparedError += std::abs(int(snell::toByte(gpu.image.pixel(x, y)[k])) -
                                          int(snell::toByte(exact.pixel(x, y)[k])));
            if (worst <= kBadThreshold) continue;
            if (illConditionedAt(cpu, reference, exact, x, y)) {
                ++illConditioned;
                excluded[i] = 1;
                continue;
            }
            ++bad;
            if (referenceBound[i] > kCertified) ++provenWrong;
            // The stated bound covers where the tree stopped, not float32
            // rounding: it is held exactly by the fp64 shader (and by the CPU
            // in tests/test_truncation.cpp).
            if (c.precision == snell::gpu::Precision::Fp64 &&
                worst > 255.0 * (gpuBound[i] + referenceBound[i]) + 1.0 && boundViolations++ < 5)
                ADD_FAILURE() << "pixel (" << x << ", " << y << ") off by " << worst << "/255, beyond the stated bounds "
                              << 255.0 * gpuBound[i] << "/255 (GPU) and " << 255.0 * referenceBound[i]
                              << "/255 (reference)";
        }
    }
    const std::uint64_t compared = m.pixels - uncertified - illConditioned;
    const double meanError = compared ? comparedError / (3.0 * double(compared + illConditioned)) : 0.0;
    // Speckles (acne, self-intersection): off by more than 8/255 with all
    // eight neighbours within 2/255, where the reference certifies the pixel.
    // (An uncertified pixel outside the reference's bounds is bad above; there
    // an isolated pixel is a diverging orbit of light in an amplifying
    // material, which float32 geometry may miss where double finds it.)
    std::uint64_t speckles = 0;
    for (int y = 1; y + 1 < c.size; ++y) {
        for (int x = 1; x + 1 < c.size; ++x) {
            const std::size_t i = std::size_t(y) * c.size + x;
            if (excluded[i] || referenceBound[i] > kCertified || worstDifference(gpu.image, exact, x, y) <= 8) continue;
            bool isolated = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if ((dx || dy) && worstDifference(gpu.image, exact, x + dx, y + dy) > 2) isolated = false;
            speckles += isolated;
        }
    }
    const double badFraction = compared ? double(bad) / double(compared) : 0.0;
    const double illFraction = double(illConditioned) / double(m.pixels);
    std::cout << "[ metrics ] " << fs::path(c.path).filename().string() << " " << m.json()
              << " compared_mean_abs_error=" << meanError << " bad=" << bad << " of " << compared
              << " (below the reference's lower bound or above its upper bound: " << provenWrong << ")"
              << " ill_conditioned_left_out=" << illConditioned << " uncertified_left_out=" << uncertified
              << " speckles_counted=" << speckles << " gpu_ms=" << gpu.renderMs << " cpu_ms=" << cpuMs << "\n";

    const bool pass = m.nonFinite == 0 && (speckles == 0 || !c.noSpeckles) && meanError <= kMaxMeanError &&
                      badFraction <= kMaxBadFraction && boundViolations == 0 && illFraction <= kMaxIllConditioned;
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
                                << " ill-conditioned or uncertified)" << artifacts;
    }
    EXPECT_LE(meanError, kMaxMeanError) << "over the " << compared << " pixels compared" << artifacts;
    EXPECT_LE(badFraction, kMaxBadFraction) << "bad pixels " << bad << " of " << compared << " compared ("
                                            << provenWrong << " outside the reference's bounds; ill-conditioned "
                                            << "left out " << illConditioned << ", uncertified left out "
                                            << uncertified << ")" << artifacts;
    EXPECT_LE(illFraction, kMaxIllConditioned) << illConditioned << " pixels left out as ill-conditioned" << artifacts;
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
