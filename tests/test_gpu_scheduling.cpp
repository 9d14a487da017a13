// The kernel's scheduling paths trace the image of the plain path, bit for
// bit: suspending and resuming (the loop budget a driver that limits loops
// imposes), the ray and media stacks through addresses or storage buffers, a
// GPU's plan on lavapipe, shadow rays shared out in a subgroup; and what the
// renderer reports while it schedules (each pixel's rays, the tiles' shares,
// interleaved tiles). Where the device cannot take a path a test names, the
// test is skipped saying why, and fails under CI (gpu_test_support.h).
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpu/ComputeRenderer.h"
#include "gpu/DriverProbe.h"
#include "gpu_test_support.h"
#include "image/ImageIO.h"
#include "scene/Parser.h"
#include "vulkan/VulkanContext.h"

namespace {

using snell::testing::context;
using snell::testing::pixelsThatDiffer;
using snell::testing::requireTheSameWalk;
using snell::testing::wholeImage;

// The invocations' suspend-and-resume path (taken where the driver limits
// loops: old llvmpipe) gives the very image of one uninterrupted dispatch,
// however often it suspends: mid-tree with nested media (glass), deep
// amplifying trees (becker-1n), mid-way through the lights (256-lights), in
// the BVH (grid), with supersampling (showcase). At 24², as each invocation
// takes fewer pixels the fewer there are, and so suspends fewer times.
class GpuResume : public testing::TestWithParam<const char*> {};

TEST_P(GpuResume, SuspendingNeverChangesTheImage) {
    const snell::Scene scene = snell::parseSceneFile(GetParam());
    const snell::RenderRequest request = wholeImage(scene, 24);
    snell::ComputeRenderer gpu(context(), scene, request.camera);
    const snell::GpuRenderResult whole = gpu.render(request, false);
    snell::ComputeRenderer budgeted(context(), scene, request.camera, {.loopBudget = 48});
    const snell::GpuRenderResult resumed = budgeted.render(request, false);
    EXPECT_GT(resumed.dispatches, 2 * whole.dispatches) << "the budget forced too few suspensions to test";
    EXPECT_EQ(resumed.image.rgb, whole.image.rgb);
}

// The same in fp64, where a ray that waits between dispatches is stored as
// floats: its doubles come back exact, so becker-1n's deep amplifying trees,
// whose light follows orbits that magnify any change, give the image of one
// uninterrupted dispatch (kept as float pairs, they did not).
TEST(GpuResumeFp64, WaitingRaysComeBackExact) {
    if (!context().float64Supported()) SNELL_CANNOT_TEST_HERE("this device has no shader doubles");
    const snell::Scene scene = snell::parseSceneFile(SNELL_SHARED_DIR "/course-scenes/becker-1n.scn");
    const snell::RenderRequest request = wholeImage(scene, 32);
    snell::ComputeRenderer gpu(context(), scene, request.camera, {.precision = snell::gpu::Precision::Fp64});
    const snell::GpuRenderResult whole = gpu.render(request, false);
    snell::ComputeRenderer budgeted(context(), scene, request.camera,
                                    {.precision = snell::gpu::Precision::Fp64, .loopBudget = 48});
    const snell::GpuRenderResult resumed = budgeted.render(request, false);
    EXPECT_GT(resumed.dispatches, 2 * whole.dispatches) << "the budget forced too few suspensions to test";
    EXPECT_EQ(pixelsThatDiffer(whole.image, resumed.image), 0u) << "pixels that differ once suspended";
}

// A scene file's stem, as a test's name.
std::string stemOf(const std::string& file) {
    std::string n = std::filesystem::path(file).stem().string();
    for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return n;
}

INSTANTIATE_TEST_SUITE_P(Scenes, GpuResume,
                         testing::Values(SNELL_SOURCE_DIR "/scenes/glass.scn",
                                         SNELL_SHARED_DIR "/course-scenes/becker-1n.scn",
                                         SNELL_SOURCE_DIR "/scenes/hard/256-lights.scn",
                                         SNELL_SOURCE_DIR "/scenes/grid.scn", SNELL_SOURCE_DIR "/scenes/showcase.scn"),
                         [](const testing::TestParamInfo<const char*>& info) { return stemOf(info.param); });

// What the progress bar's estimate takes from the renderer: each pixel's rays
// (its closest-hit queries: the rays the progress reports, but for the shadow
// rays), the render's rays in all, and with an expected cost the share of each
// tile done, which never changes the image.
void checkPixelRaysAndShares(const std::string& scenePath) {
    const snell::Scene scene = snell::parseSceneFile(scenePath);
    snell::RenderRequest request;
    request.width = request.height = 48;
    request.camera = snell::Camera::fromSpec(48, scene.halfWidth);
    request.trace = snell::kDefaultSettings;
    snell::ComputeRenderer gpu(context(), scene, request.camera);
    std::vector<float> pixelRays;
    request.rayImage = &pixelRays;
    std::uint64_t reportedRays = 0;
    request.progress = [&](double, std::uint64_t rays) { reportedRays = rays; };
    const snell::GpuRenderResult counted = gpu.render(request, true);
    ASSERT_EQ(pixelRays.size(), std::size_t(48 * 48));
    double sum = 0.0;
    for (float r : pixelRays) {
        EXPECT_GE(r, 1.0f);  // the camera ray at least
        sum += r;
    }
    EXPECT_EQ(sum + double(counted.rays.shadow), double(reportedRays));
    // The render's total of them, the progress bar's probe's cost, needs no
    // counting build (so the probe compiles the render's own pipeline).
    EXPECT_EQ(counted.tracedRays, reportedRays);
    EXPECT_EQ(gpu.render(request, false).tracedRays, reportedRays);

    // The cost map, one cell per 4 × 4 pixels, from those rays.
    snell::CostMap cost{4, 12, 12, std::vector<float>(12 * 12, 0.0f)};
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x) cost.cells[(y / 4) * 12 + x / 4] += pixelRays[y * 48 + x];
    std::vector<double> shares;
    request.rayImage = nullptr;
    request.expectedCost = &cost;
    request.progress = [&](double fraction, std::uint64_t) { shares.push_back(fraction); };
    const snell::GpuRenderResult weighed = gpu.render(request, false);
    ASSERT_FALSE(shares.empty());
    for (double f : shares) {
        EXPECT_GE(f, 0.0);
        EXPECT_LE(f, 1.0);
    }
    EXPECT_EQ(shares.back(), 1.0);
    EXPECT_EQ(weighed.image.rgb, counted.image.rgb);
}

// Refraction: workgroups help with each other's shares (trace.comp,
// takePixel), and the tile's progress is its cost done.
TEST(GpuProgress, PixelRaysAndSharesOfTheTile) { checkPixelRaysAndShares(SNELL_SOURCE_DIR "/scenes/glass.scn"); }

// Neither refraction nor a BVH: each workgroup keeps to its share, and the
// tile's progress comes from its workgroups' schedule.
TEST(GpuProgress, PixelRaysAndSharesOfATileOfOwnShares) {
    checkPixelRaysAndShares(SNELL_SOURCE_DIR "/scenes/mirrors.scn");
}


// Interleaved tiles (each every other run of columns and rows of the window)
// cover the window's pixels once each, and give the very image, bounds and
// pixel costs of tiles in blocks, streamed or whole; the probe's regions
// split the window between them by their pixels.
TEST(GpuTiles, InterleavedTilesGiveTheImageOfBlocks) {
    const snell::PixelWindow window{5, 0, 1100, 1090};  // runs that do not divide it
    const std::vector<snell::RenderRegion> regions = snell::ComputeRenderer::tiles(window, true);
    ASSERT_EQ(regions.size(), 4u);
    double shares = 0.0;
    for (const snell::RenderRegion& r : regions) {
        EXPECT_EQ(r.window.x0, window.x0);
        EXPECT_EQ(r.window.y1, window.y1);
        shares += r.share;
    }
    EXPECT_NEAR(shares, 1.0, 1e-12);
    EXPECT_EQ(snell::ComputeRenderer::tiles(window, false)[1].window.x0, window.x0 + snell::ComputeRenderer::kMaxTileSide);

    const snell::Scene scene = snell::parseSceneFile(SNELL_SOURCE_DIR "/scenes/example.scn");
    snell::ComputeRenderer gpu(context(), scene, snell::Camera::fromSpec(1100, scene.halfWidth));
    struct Rendered {
        snell::Image image;
        std::vector<float> bound, rays;
        std::vector<double> fractions;
    };
    auto render = [&](bool interleaved, bool streamed) {
        snell::RenderRequest request;
        request.width = request.height = 1100;
        request.window = window;
        request.camera = snell::Camera::fromSpec(1100, scene.halfWidth);
        request.trace = snell::kDefaultSettings;
        request.interleavedTiles = interleaved;
        Rendered out;
        request.boundImage = &out.bound;
        request.rayImage = &out.rays;
        request.progress = [&](double fraction, std::uint64_t) { out.fractions.push_back(fraction); };
        std::vector<float> rows;
        if (streamed) request.rowSink = [&](const float* rgb, int n) { rows.insert(rows.end(), rgb, rgb + n * window.width() * 3); };
        snell::GpuRenderResult result = gpu.render(request, false);
        EXPECT_EQ(result.tiles, 4);
        EXPECT_EQ(result.interleaved, interleaved);
        out.image = std::move(result.image);
        if (streamed) out.image.rgb = rows;
        return out;
    };
    const Rendered blocks = render(false, false);
    ASSERT_EQ(blocks.image.rgb.size(), std::size_t(window.width()) * window.height() * 3);
    for (bool streamed : {false, true}) {
        SCOPED_TRACE(streamed ? "streamed" : "whole");
        const Rendered interleaved = render(true, streamed);
        EXPECT_EQ(interleaved.image.rgb, blocks.image.rgb);
        EXPECT_EQ(interleaved.bound, blocks.bound);
        EXPECT_EQ(interleaved.rays, blocks.rays);
        ASSERT_FALSE(interleaved.fractions.empty());
        EXPECT_EQ(interleaved.fractions.back(), 1.0);
        EXPECT_TRUE(std::is_sorted(interleaved.fractions.begin(), interleaved.fractions.end()));
    }
}


// The ray and media stacks are read and written through their device
// addresses or as storage buffers, whichever the driver does faster
// (trace.comp, storePending): both trace the same image, bit for bit, also
// where the invocations suspend mid-tree and the stacks carry their rays from
// one dispatch to the next; nested media (glass in water), amplifying trees
// (becker-1n), a BVH, the fp64 kernel (its low parts stay in a storage
// buffer), and the deepest stack of a fixed tree without a cut-off.
struct StackCase {
    const char* name;
    const char* file;
    snell::gpu::Precision precision;
    bool fixedTree;  // --depth 5 --min-weight 0 --tolerance 0 (POV-Ray's settings)
};

class GpuStacks : public testing::TestWithParam<StackCase> {};

TEST_P(GpuStacks, AddressesTraceTheStorageBuffersImage) {
    const StackCase& c = GetParam();
    if (c.precision == snell::gpu::Precision::Fp64 && !context().float64Supported())
        SNELL_CANNOT_TEST_HERE("this device has no shader doubles");
    const snell::Scene scene = snell::parseSceneFile(c.file);
    constexpr int size = 32;
    snell::RenderRequest request = wholeImage(scene, size);
    if (c.fixedTree) {
        request.trace.maxDepth = 5;
        request.trace.minWeight = 0.0;
        request.trace.tolerance = 0.0;
    }
    std::vector<snell::Image> images;
    for (const bool byAddress : {false, true}) {
        snell::ComputeRenderer renderer(context(), scene, request.camera,
                                        {.precision = c.precision, .addressStacks = byAddress});
        const snell::GpuRenderResult whole = renderer.render(request, false);
        EXPECT_EQ(renderer.kernelAddressedStacks(), byAddress);
        snell::ComputeRenderer budgeted(context(), scene, request.camera,
                                        {.precision = c.precision, .loopBudget = 48, .addressStacks = byAddress});
        const snell::GpuRenderResult resumed = budgeted.render(request, false);
        EXPECT_GT(resumed.dispatches, 2 * whole.dispatches) << "the budget forced too few suspensions to test";
        ASSERT_EQ(whole.image.rgb.size(), std::size_t(3 * size * size));
        ASSERT_EQ(resumed.image.rgb.size(), whole.image.rgb.size());
        EXPECT_EQ(pixelsThatDiffer(whole.image, resumed.image), 0u) << "pixels that differ once suspended";
        images.push_back(whole.image);
    }
    EXPECT_EQ(pixelsThatDiffer(images[0], images[1]), 0u) << "pixels that differ between the stacks";
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, GpuStacks,
    testing::Values(StackCase{"glass", SNELL_SOURCE_DIR "/scenes/glass.scn", snell::gpu::Precision::Fp32, false},
                    StackCase{"glass_fp64", SNELL_SOURCE_DIR "/scenes/glass.scn", snell::gpu::Precision::Fp64, false},
                    StackCase{"glass_in_water_gap_0", SNELL_SOURCE_DIR "/scenes/hard/glass-in-water-gap-0.scn",
                              snell::gpu::Precision::Fp32, false},
                    StackCase{"becker_1n", SNELL_SHARED_DIR "/course-scenes/becker-1n.scn",
                              snell::gpu::Precision::Fp32, false},
                    StackCase{"grid", SNELL_SOURCE_DIR "/scenes/grid.scn", snell::gpu::Precision::Fp32, false},
                    StackCase{"bench_glass_fixed_tree", SNELL_SHARED_DIR "/bench-scenes/glass.scn",
                              snell::gpu::Precision::Fp32, true}),
    [](const testing::TestParamInfo<StackCase>& info) { return std::string(info.param.name); });

// The shadow rays of a subgroup's hits are walked by all its lanes, or each
// by its own lane in the lights' loop (trace.comp, shadeLightsShared): both
// trace the same image, bit for bit, and count the same rays. Every scene
// here has more than one light; in SphereFlake2's glass few lanes of a
// subgroup cast shadow rays; lights-over-glass-bvh has more lights than one
// batch holds, and lights that some surfaces face only from below.
TEST(GpuShadowRays, SharedTraceTheOwnRaysImage) {
    // Only on a CPU device with subgroups of 2 to 16 lanes, and not where the
    // driver ends long loops (the walk must be able to suspend there):
    // elsewhere both renders would run the same kernel.
    {
        const snell::Scene grid = snell::parseSceneFile(SNELL_SOURCE_DIR "/scenes/grid.scn");
        const snell::ComputeRenderer probe(context(), grid, wholeImage(grid, 8).camera, {.shareShadowRays = true});
        if (!probe.sharesShadowRays())
            SNELL_CANNOT_TEST_HERE("this device does not share shadow rays out (" + context().deviceName() +
                                   ", subgroups of " + std::to_string(context().subgroupSize()) +
                                   " lanes, loops limited: " +
                                   (snell::limitsLoopIterations(context()) ? "yes" : "no") + ")");
    }
    requireTheSameWalk({{SNELL_SOURCE_DIR "/scenes/grid.scn", snell::gpu::Precision::Fp32},
                        {SNELL_SOURCE_DIR "/scenes/grid.scn", snell::gpu::Precision::Fp64},
                        {SNELL_SOURCE_DIR "/scenes/hard/lights-over-glass-bvh.scn", snell::gpu::Precision::Fp32},
                        {SNELL_SHARED_DIR "/course-scenes/becker-SphereFlake2.scn", snell::gpu::Precision::Fp32}},
                       [](snell::RendererOptions& options, bool share) { options.shareShadowRays = share; },
                       "shared and own shadow rays", true, [](const snell::ComputeRenderer& renderer, bool share) {
                           // The setting took: the two renders run different kernels.
                           EXPECT_EQ(renderer.sharesShadowRays(), share);
                       });
}

// A GPU's plan (thousands of workgroups taking the tile's shares, helping
// with each other's through the shares' bits, their words' bits over more
// than one word) traces each pixel as lavapipe's plan does: the same image
// for a fixed tree. (Under a tolerance a GPU's shorter frontier traces some
// rays a step early, so the trees, and the last bits, may differ.) On a
// driver that limits loops (Mesa 22.3) this also checks the loop budget's
// count of the share search's loops: counted too few, the driver cut a BVH
// walk short and 3 pixels of grid came out as background.
TEST(GpuPlan, TracesTheImageOfLavapipesPlan) {
    // On a GPU the renderer plans as a GPU anyway: both renders would be one.
    if (!context().isCpuDevice())
        SNELL_CANNOT_TEST_HERE("planAsGpu changes nothing on a GPU (" + context().deviceName() + ")");
    for (const char* file : {SNELL_SOURCE_DIR "/scenes/grid.scn", SNELL_SOURCE_DIR "/scenes/glass.scn"}) {
        SCOPED_TRACE(file);
        const snell::Scene scene = snell::parseSceneFile(file);
        snell::RenderRequest request = wholeImage(scene, 512);
        request.trace.tolerance = 0.0;
        snell::ComputeRenderer gpu(context(), scene, request.camera);
        const snell::GpuRenderResult own = gpu.render(request, false);
        snell::ComputeRenderer asGpu(context(), scene, request.camera, {.planAsGpu = true});
        const snell::GpuRenderResult planned = asGpu.render(request, false);
        // The plan took: a GPU's has many more invocations than lavapipe's.
        EXPECT_LT(own.invocations, planned.invocations);
        // grid: more shares than 32 words of bits, so the words' bits span words too.
        if (scene.spheres.size() > snell::gpu::kBvhThreshold) {
            EXPECT_GT(planned.invocations, 32 * 32 * SNELL_WORKGROUP_SIZE);
        }
        ASSERT_EQ(planned.image.rgb.size(), own.image.rgb.size());
        EXPECT_EQ(pixelsThatDiffer(own.image, planned.image), 0u) << "pixels that differ between the plans";
    }
}

}  // namespace
