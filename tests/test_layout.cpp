// The std430 layout shared with the shader (shaders/shared_layout.h), checked
// at run time so that a mismatch shows up in ctest, and buildGpuScene.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <set>
#include <vector>

#include "gpu/GpuScene.h"
#include "scene/Parser.h"

namespace {

namespace gpu = snell::gpu;

TEST(Layout, Sphere) {
    EXPECT_EQ(sizeof(gpu::Sphere), 32u);
    EXPECT_EQ(offsetof(gpu::Sphere, anchorRadius), 0u);
    EXPECT_EQ(offsetof(gpu::Sphere, normal), 16u);
    EXPECT_EQ(sizeof(gpu::SphereBlock), 32u * SNELL_BLOCK_SPHERES);
}

// An ellipsoid's sphere carries −1 − its index in anchorRadius.w.
bool isEllipsoid(const gpu::Sphere& s) { return s.anchorRadius.w < 0.0f; }
std::uint32_t ellipsoidIndex(const gpu::Sphere& s) { return static_cast<std::uint32_t>(-s.anchorRadius.w) - 1; }

// A GPU sphere's centre: anchor − r·n0 for a true sphere, the stored centre
// of an ellipsoid.
glm::vec3 centreOf(const gpu::Sphere& s) {
    if (isEllipsoid(s)) return glm::vec3(s.anchorRadius);
    return glm::vec3(s.anchorRadius) - s.anchorRadius.w * glm::vec3(s.normal);
}

// An ellipsoid's objectFromWorld, from its three rows.
glm::mat4 matrixOf(const gpu::Ellipsoid& e) {
    return glm::transpose(glm::mat4(e.row0, e.row1, e.row2, glm::vec4(0, 0, 0, 1)));
}

TEST(Layout, Ellipsoid) {
    EXPECT_EQ(sizeof(gpu::Ellipsoid), 48u);
    EXPECT_EQ(offsetof(gpu::Ellipsoid, row0), 0u);
    EXPECT_EQ(offsetof(gpu::Ellipsoid, row1), 16u);
    EXPECT_EQ(offsetof(gpu::Ellipsoid, row2), 32u);
}

TEST(Layout, Material) {
    EXPECT_EQ(sizeof(gpu::Material), 48u);
    EXPECT_EQ(offsetof(gpu::Material, kd), 0u);
    EXPECT_EQ(offsetof(gpu::Material, ks), 16u);
    EXPECT_EQ(offsetof(gpu::Material, kt), 32u);
}

TEST(Layout, Light) {
    EXPECT_EQ(sizeof(gpu::Light), 32u);
    EXPECT_EQ(offsetof(gpu::Light, position), 0u);
    EXPECT_EQ(offsetof(gpu::Light, colour), 16u);
}

TEST(Layout, BvhNode) {
    EXPECT_EQ(sizeof(gpu::BvhNode), 16u * SNELL_BVH_NODE_TEXELS);
    EXPECT_EQ(offsetof(gpu::BvhNode, lowerX), 0u);
    EXPECT_EQ(offsetof(gpu::BvhNode, upperX), 16u);
    EXPECT_EQ(offsetof(gpu::BvhNode, lowerZ), 64u);
    EXPECT_EQ(offsetof(gpu::BvhNode, child), 96u);
}

// Child k's code (uint bits) and box corners.
std::uint32_t childOf(const gpu::BvhNode& n, int k) { return std::bit_cast<std::uint32_t>(n.child[k]); }
glm::vec3 lowerOf(const gpu::BvhNode& n, int k) { return {n.lowerX[k], n.lowerY[k], n.lowerZ[k]}; }
glm::vec3 upperOf(const gpu::BvhNode& n, int k) { return {n.upperX[k], n.upperY[k], n.upperZ[k]}; }

TEST(Layout, FrameParams) {
    EXPECT_EQ(sizeof(gpu::FrameParams), 240u + 32u * SNELL_FRAME_LIGHTS);
    EXPECT_EQ(offsetof(gpu::FrameParams, lights), 240u);
    EXPECT_EQ(offsetof(gpu::FrameParams, primaryStart), 0u);
    EXPECT_EQ(offsetof(gpu::FrameParams, cornerDir), 16u);
    EXPECT_EQ(offsetof(gpu::FrameParams, pixelRight), 32u);
    EXPECT_EQ(offsetof(gpu::FrameParams, pixelDown), 48u);
    EXPECT_EQ(offsetof(gpu::FrameParams, background), 64u);
    EXPECT_EQ(offsetof(gpu::FrameParams, ambient), 80u);
    EXPECT_EQ(offsetof(gpu::FrameParams, radiance), 96u);
    EXPECT_EQ(offsetof(gpu::FrameParams, localRadiance), 112u);
    EXPECT_EQ(offsetof(gpu::FrameParams, imageWidth), 128u);
    EXPECT_EQ(offsetof(gpu::FrameParams, imageHeight), 132u);
    EXPECT_EQ(offsetof(gpu::FrameParams, supersample), 136u);
    EXPECT_EQ(offsetof(gpu::FrameParams, maxDepth), 140u);
    EXPECT_EQ(offsetof(gpu::FrameParams, sphereCount), 144u);
    EXPECT_EQ(offsetof(gpu::FrameParams, lightCount), 148u);
    EXPECT_EQ(offsetof(gpu::FrameParams, bvhNodeCount), 152u);
    EXPECT_EQ(offsetof(gpu::FrameParams, firstSample), 156u);
    EXPECT_EQ(offsetof(gpu::FrameParams, sampleCount), 160u);
    EXPECT_EQ(offsetof(gpu::FrameParams, treeBudget), 164u);
    EXPECT_EQ(offsetof(gpu::FrameParams, estimate), 168u);
    EXPECT_EQ(offsetof(gpu::FrameParams, minWeight), 172u);
    EXPECT_EQ(offsetof(gpu::FrameParams, tolerance), 176u);
    EXPECT_EQ(offsetof(gpu::FrameParams, amplifiedEstimate), 180u);
    EXPECT_EQ(offsetof(gpu::FrameParams, airEta), 184u);
    EXPECT_EQ(offsetof(gpu::FrameParams, bvhAddressLow), 188u);
    EXPECT_EQ(offsetof(gpu::FrameParams, bvhAddressHigh), 192u);
    EXPECT_EQ(offsetof(gpu::FrameParams, rayStackAddressLow), 196u);
    EXPECT_EQ(offsetof(gpu::FrameParams, rayStackAddressHigh), 200u);
    EXPECT_EQ(offsetof(gpu::FrameParams, mediaStackAddressLow), 204u);
    EXPECT_EQ(offsetof(gpu::FrameParams, mediaStackAddressHigh), 208u);
    EXPECT_EQ(offsetof(gpu::FrameParams, sphereExtent), 212u);
    EXPECT_EQ(offsetof(gpu::FrameParams, flaggedAddressLow), 216u);
    EXPECT_EQ(offsetof(gpu::FrameParams, reachInward), 224u);
}

TEST(Layout, TileParams) {
    EXPECT_EQ(sizeof(gpu::TileParams), 32u);
    EXPECT_EQ(offsetof(gpu::TileParams, originX), 0u);
    EXPECT_EQ(offsetof(gpu::TileParams, originY), 4u);
    EXPECT_EQ(offsetof(gpu::TileParams, width), 8u);
    EXPECT_EQ(offsetof(gpu::TileParams, height), 12u);
    EXPECT_EQ(offsetof(gpu::TileParams, resume), 16u);
    EXPECT_EQ(offsetof(gpu::TileParams, strideX), 24u);
    EXPECT_EQ(offsetof(gpu::TileParams, strideY), 28u);
}

TEST(Layout, SlotStateAndPendingRay) {
    EXPECT_EQ(sizeof(gpu::SlotState), 256u);
    EXPECT_EQ(offsetof(gpu::SlotState, sampleLight), 192u);
    EXPECT_EQ(offsetof(gpu::SlotState, flaggedHigh), 228u);
    EXPECT_EQ(offsetof(gpu::SlotState, undecidedLocal), 236u);
    EXPECT_EQ(offsetof(gpu::SlotState, deferredLight), 240u);
    EXPECT_EQ(sizeof(gpu::SphereReach), 32u);
    EXPECT_EQ(sizeof(gpu::FlaggedSamples), 32u);
    EXPECT_EQ(offsetof(gpu::FlaggedSamples, low), 16u);
    EXPECT_EQ(offsetof(gpu::SlotState, deferred), 16u);
    EXPECT_EQ(offsetof(gpu::SlotState, lower), 48u);
    EXPECT_EQ(offsetof(gpu::SlotState, settled), 80u);
    EXPECT_EQ(offsetof(gpu::SlotState, undecided), 96u);
    EXPECT_EQ(offsetof(gpu::SlotState, pixel), 112u);
    EXPECT_EQ(offsetof(gpu::SlotState, finished), 124u);
    EXPECT_EQ(offsetof(gpu::SlotState, treeRays), 128u);
    EXPECT_EQ(offsetof(gpu::SlotState, frontierHead), 144u);
    EXPECT_EQ(offsetof(gpu::SlotState, amplified), 156u);
    EXPECT_EQ(offsetof(gpu::SlotState, cutOff), 160u);
    EXPECT_EQ(offsetof(gpu::SlotState, heaviestLeft), 164u);
    EXPECT_EQ(offsetof(gpu::SlotState, lastMove), 168u);
    EXPECT_EQ(offsetof(gpu::SlotState, moveBefore), 172u);
    EXPECT_EQ(offsetof(gpu::SlotState, settledWeight), 176u);
    EXPECT_EQ(sizeof(gpu::OutputPixel), 32u);
    EXPECT_EQ(offsetof(gpu::OutputPixel, estimate), 16u);
    EXPECT_EQ(offsetof(gpu::OutputPixel, report), 20u);
    EXPECT_EQ(offsetof(gpu::OutputPixel, excess), 24u);
    EXPECT_EQ(offsetof(gpu::OutputPixel, moved), 28u);
    EXPECT_EQ(sizeof(gpu::PendingRay), 64u);
    EXPECT_EQ(offsetof(gpu::PendingRay, weight), 32u);
    EXPECT_EQ(offsetof(gpu::PendingRay, depth), 48u);
    EXPECT_EQ(offsetof(gpu::PendingRay, flags), 56u);
    EXPECT_EQ(offsetof(gpu::PendingRay, resumeShading), 60u);
}

// The counters buffer: the shares' bits after every workgroup's counters, one
// bit a workgroup; the words' bits after them, one a word; nothing overlaps.
TEST(Layout, ShareBitsFollowTheWorkgroupsCounters) {
    for (std::uint64_t groups : {1u, 31u, 32u, 33u, 1024u, 1025u, 4297u}) {
        const std::uint64_t words = (groups + 31) / 32;
        EXPECT_EQ(SNELL_SHARE_WORDS(groups), words) << groups;
        EXPECT_EQ(SNELL_SHARE_BITS_AT(groups), SNELL_COUNTER_COUNT + groups * SNELL_COUNTER_STRIDE) << groups;
        EXPECT_EQ(SNELL_WORD_BITS_AT(groups), SNELL_SHARE_BITS_AT(groups) + words) << groups;
        EXPECT_EQ(SNELL_COUNTERS_FOR(groups), SNELL_WORD_BITS_AT(groups) + (words + 31) / 32) << groups;
    }
}

TEST(Layout, ArrayStridesAreVec4Multiples) {
    // std430 arrays of structs containing vec4 have a stride that is a multiple of 16.
    EXPECT_EQ(sizeof(gpu::Sphere) % 16, 0u);
    EXPECT_EQ(sizeof(gpu::Ellipsoid) % 16, 0u);
    EXPECT_EQ(sizeof(gpu::Material) % 16, 0u);
    EXPECT_EQ(sizeof(gpu::Light) % 16, 0u);
    EXPECT_EQ(sizeof(gpu::BvhNode) % 16, 0u);
    EXPECT_EQ(sizeof(gpu::vec4), 16u);
    EXPECT_EQ(sizeof(gpu::uint), 4u);
}

// ---------------------------------------------------------------- buildGpuScene

snell::Scene parse(const std::string& text) { return snell::parseScene(text, "t.scn"); }

void expectVec(const glm::vec4& v, float x, float y, float z, float w) {
    EXPECT_FLOAT_EQ(v.x, x);
    EXPECT_FLOAT_EQ(v.y, y);
    EXPECT_FLOAT_EQ(v.z, z);
    EXPECT_FLOAT_EQ(v.w, w);
}

TEST(GpuScene, SmallSceneIsOriginRelativeAndClassified) {
    const snell::Scene s = parse("view 10 1\nmove 1 2 3\ngroup\nmaterial 0.1 0.2 0.3 0.4 0.5 0.6 7\n"
                                 "refraction 0.3 0.3 0.3 1.5\nscale 2 2 2\nsphere\ngroupend\n"
                                 "scale 1 2 1\nsphere\nlight 0.7 0.8 0.9 4 5 6\n");
    const snell::Camera camera = snell::Camera::fromSpec(s.imageSize, s.halfWidth);
    const gpu::GpuScene g = gpu::buildGpuScene(s, camera);
    EXPECT_EQ(g.eye, snell::dvec3(0, 0, 1));
    ASSERT_EQ(g.spheres.size(), 2u);
    EXPECT_TRUE(g.nodes.empty());  // 2 spheres: no BVH, order kept

    // The origin: where primary rays start, just before the nearest bounding
    // sphere (the ellipsoid's: centre distance 3, bounding radius √6).
    const double nearest = 3.0 - std::sqrt(6.0);
    EXPECT_LT(g.primaryStart, nearest);
    EXPECT_GT(g.primaryStart, nearest - 1e-3 * std::sqrt(6.0) - 1e-6);  // margin: a sliver of its size
    EXPECT_EQ(g.origin, g.eye + g.primaryStart * camera.forward);
    const glm::vec3 o(g.origin);
    auto rel = [&](double x, double y, double z) { return glm::vec3(x, y, z) - o; };

    // True sphere: centre (1,2,3), radius 2, anchored at its point nearest the
    // origin with the outward normal there.
    EXPECT_FALSE(isEllipsoid(g.spheres[0]));
    EXPECT_FLOAT_EQ(g.spheres[0].anchorRadius.w, 2.0f);
    const glm::vec3 c0 = rel(1, 2, 3);
    const glm::vec3 n0 = -glm::normalize(c0);
    EXPECT_NEAR(glm::length(glm::vec3(g.spheres[0].normal) - n0), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(glm::vec3(g.spheres[0].anchorRadius) - (c0 + 2.0f * n0)), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(centreOf(g.spheres[0]) - c0), 0.0f, 1e-5f);
    EXPECT_NEAR(g.spheres[0].normal.w, glm::length(c0 + 2.0f * n0), 1e-5f);  // |P0|
    // Ellipsoid: its centre and index, the norm of its matrix, and the matrix.
    ASSERT_EQ(g.ellipsoids.size(), 1u);
    ASSERT_TRUE(isEllipsoid(g.spheres[1]));
    EXPECT_EQ(ellipsoidIndex(g.spheres[1]), 0u);
    EXPECT_NEAR(glm::length(centreOf(g.spheres[1]) - rel(1, 2, 3)), 0.0f, 1e-6f);
    EXPECT_FLOAT_EQ(g.spheres[1].normal.w, 1.0f);  // diag(1, 1/2, 1): largest row sum 1
    // Its matrix maps origin-relative points to object space: the world point
    // (1, 4, 3) is the top of the ellipsoid.
    const glm::vec4 top = matrixOf(g.ellipsoids[0]) * glm::vec4(rel(1, 4, 3), 1);
    EXPECT_NEAR(top.x, 0.0f, 1e-6f);
    EXPECT_NEAR(top.y, 1.0f, 1e-6f);
    EXPECT_NEAR(top.z, 0.0f, 1e-6f);
    const glm::vec4 centre = matrixOf(g.ellipsoids[0]) * glm::vec4(rel(1, 2, 3), 1);
    EXPECT_NEAR(glm::length(glm::vec3(centre)), 0.0f, 1e-6f);

    // Materials and lights.
    ASSERT_EQ(g.materials.size(), s.materials.size());
    ASSERT_EQ(g.sphereMaterials.size(), 2u);
    const gpu::Material& glass = g.materials[g.sphereMaterials[0]];
    expectVec(glass.kd, 0.1f, 0.2f, 0.3f, 7.0f);  // w = Phong exponent
    EXPECT_FLOAT_EQ(glass.ks.y, 0.5f);
    expectVec(glass.kt, 0.3f, 0.3f, 0.3f, 1.5f);  // w = eta
    const gpu::Material& plain = g.materials[g.sphereMaterials[1]];
    expectVec(plain.kd, 1, 1, 1, 1);
    EXPECT_FLOAT_EQ(plain.kt.w, static_cast<float>(snell::kAirEta));
    EXPECT_EQ(g.refractiveSpheres, 1u);
    EXPECT_FALSE(g.amplifying);
    ASSERT_EQ(g.lights.size(), 1u);
    EXPECT_NEAR(glm::length(glm::vec3(g.lights[0].position) - rel(4, 5, 6)), 0.0f, 1e-6f);
    EXPECT_FLOAT_EQ(g.lights[0].colour.r, 0.7f);
    EXPECT_FLOAT_EQ(g.lights[0].colour.b, 0.9f);

    snell::RenderRequest request;
    request.camera = camera;
    request.width = request.height = 10;
    request.trace = {.maxDepth = 32, .minWeight = 1e-4, .tolerance = 0.002};
    const gpu::FrameParams f = gpu::makeFrameParams(s, g, request);
    EXPECT_EQ(f.maxDepth, 32u);
    EXPECT_FLOAT_EQ(f.minWeight, 1e-4f);
    EXPECT_FLOAT_EQ(f.tolerance, 0.002f);
    EXPECT_FLOAT_EQ(f.airEta, static_cast<float>(snell::kAirEta));
    EXPECT_EQ(f.supersample, 1u);
    EXPECT_EQ(f.sampleCount, 1u);
    EXPECT_EQ(f.sphereCount, 2u);
    EXPECT_EQ(f.lightCount, 1u);
    EXPECT_EQ(f.bvhNodeCount, 0u);
    EXPECT_EQ(f.imageWidth, 10u);
    EXPECT_FLOAT_EQ(f.cornerDir.x, -1.0f);
    EXPECT_FLOAT_EQ(f.cornerDir.y, 1.0f);
    EXPECT_FLOAT_EQ(f.cornerDir.z, -1.0f);
    EXPECT_FLOAT_EQ(f.pixelRight.x, 0.2f);
    EXPECT_FLOAT_EQ(f.pixelDown.y, -0.2f);
    // Primary rays start at the origin's distance, from the eye (relative to it).
    EXPECT_FLOAT_EQ(f.primaryStart.w, static_cast<float>(g.primaryStart));
    EXPECT_NEAR(glm::length(glm::vec3(f.primaryStart) - rel(0, 0, 1)), 0.0f, 1e-6f);
    // The true sphere's farthest point from the origin, rounded up (the
    // shader's sure-miss test takes it as a bound on every true sphere's).
    const double farthest = glm::length(snell::dvec3(1, 2, 3) - g.origin) + 2.0;
    EXPECT_DOUBLE_EQ(g.sphereExtent, farthest);
    EXPECT_GE(double(f.sphereExtent), farthest);
    EXPECT_LE(double(f.sphereExtent), farthest * (1.0 + 1e-6));
}

TEST(GpuScene, AmplifyingMaterialFlagged) {
    const snell::Scene s = parse("view 10 1\nmaterial 1 1 1 0.5 0.5 0.5 1\nrefraction 1 1 1 1.5\nsphere\n");
    EXPECT_TRUE(gpu::buildGpuScene(s, snell::Camera::fromSpec(10, 1)).amplifying);
}

// `count` spheres at x = 3, 6, 9, ... (unique, camera-relative x unchanged);
// every third one an ellipsoid.
std::string rowOfSpheres(std::size_t count) {
    std::string text = "view 10 1\n";
    for (std::size_t i = 0; i < count; ++i) {
        text += "move 3 0 0\n";
        text += (i % 3 == 2) ? "group\nscale 1 0.5 1\nsphere\ngroupend\n" : "sphere\n";
    }
    return text;
}

TEST(GpuScene, NoBvhAtTheThreshold) {
    const snell::Scene s = parse(rowOfSpheres(gpu::kBvhThreshold));
    const gpu::GpuScene g = gpu::buildGpuScene(s, snell::Camera::fromSpec(10, 1));
    EXPECT_TRUE(g.nodes.empty());
    ASSERT_EQ(g.spheres.size(), gpu::kBvhThreshold);
    for (std::size_t i = 0; i < g.spheres.size(); ++i)
        EXPECT_NEAR(centreOf(g.spheres[i]).x, 3.0f * (i + 1), 1e-5f);
}

TEST(GpuScene, BvhAboveTheThresholdHoldsEverySphereOnce) {
    for (std::size_t n : {gpu::kBvhThreshold + 1, std::size_t{100}}) {
        SCOPED_TRACE(n);
        const snell::Scene s = parse(rowOfSpheres(n));
        const gpu::GpuScene g = gpu::buildGpuScene(s, snell::Camera::fromSpec(10, 1));
        ASSERT_FALSE(g.nodes.empty());
        ASSERT_EQ(g.spheres.size(), n);
        EXPECT_EQ(g.ellipsoids.size(), s.ellipsoidCount());

        // Every scene sphere appears exactly once (identified by its x).
        std::multiset<int> seen;
        std::set<std::uint32_t> ellipsoidIndices;
        for (const gpu::Sphere& sp : g.spheres) {
            seen.insert(static_cast<int>(std::lround(centreOf(sp).x / 3.0f)));
            const int index = static_cast<int>(std::lround(centreOf(sp).x / 3.0f)) - 1;
            EXPECT_EQ(isEllipsoid(sp), index % 3 == 2) << "sphere at x = " << centreOf(sp).x;
            if (isEllipsoid(sp)) {
                const std::uint32_t e = ellipsoidIndex(sp);
                ASSERT_LT(e, g.ellipsoids.size());
                EXPECT_TRUE(ellipsoidIndices.insert(e).second);
                // The ellipsoid's matrix belongs to this sphere: it maps its centre to 0.
                const glm::vec4 c = matrixOf(g.ellipsoids[e]) * glm::vec4(centreOf(sp), 1.0f);
                EXPECT_NEAR(glm::length(glm::vec3(c)), 0.0f, 1e-4f);
            }
        }
        for (std::size_t i = 1; i <= n; ++i) EXPECT_EQ(seen.count(static_cast<int>(i)), 1u) << i;

        // Walked from the root through every child: each node is reached once
        // and only from a node before it, a node has at least two children
        // and its empty lanes last, the leaves cover [0, n) exactly once and
        // each child's box holds what is below it (a leaf's, its spheres'
        // bounds), the depth is the longest path, and the stack the walk
        // needs is sized from it.
        std::vector<int> covered(n, 0);
        std::vector<int> reached(g.nodes.size(), 0);
        std::size_t visited = 0;
        int deepest = 0;
        std::vector<std::pair<std::uint32_t, int>> open{{0u, 1}};
        while (!open.empty()) {
            const auto [i, depth] = open.back();
            open.pop_back();
            ASSERT_LT(i, g.nodes.size());
            ASSERT_EQ(++reached[i], 1);
            ++visited;
            deepest = std::max(deepest, depth);
            const gpu::BvhNode& node = g.nodes[i];
            int children = 0;
            for (int k = 0; k < SNELL_BVH_WIDTH; ++k) {
                const std::uint32_t code = childOf(node, k);
                if (code == SNELL_BVH_EMPTY) continue;
                EXPECT_EQ(children++, k) << "empty lanes come last";
                if ((code & SNELL_BVH_LEAF) == 0) {
                    ASSERT_GT(code, i);
                    ASSERT_LT(code, g.nodes.size());
                    const gpu::BvhNode& below = g.nodes[code];
                    for (int j = 0; j < SNELL_BVH_WIDTH; ++j) {
                        if (childOf(below, j) == SNELL_BVH_EMPTY) continue;
                        for (int a = 0; a < 3; ++a) {
                            EXPECT_LE(lowerOf(node, k)[a], lowerOf(below, j)[a]);
                            EXPECT_GE(upperOf(node, k)[a], upperOf(below, j)[a]);
                        }
                    }
                    open.push_back({code, depth + 1});
                    continue;
                }
                const std::uint32_t leaf = code & ~SNELL_BVH_LEAF;
                const std::uint32_t first = leaf >> 2, count = (leaf & 3) + 1;
                ASSERT_LE(count, std::uint32_t(SNELL_BVH_MAX_LEAF));
                for (std::uint32_t s = first; s < first + count; ++s) {
                    ASSERT_LT(s, n);
                    ++covered[s];
                    const glm::vec4 cr(centreOf(g.spheres[s]), g.spheres[s].anchorRadius.w);
                    // A true sphere's radius is exact; an ellipsoid's only bounds
                    // it, so only its centre is checked.
                    const float r = isEllipsoid(g.spheres[s]) ? 0.0f : cr.w;
                    for (int a = 0; a < 3; ++a) {
                        EXPECT_LE(lowerOf(node, k)[a], cr[a] - r + 1e-5f);
                        EXPECT_GE(upperOf(node, k)[a], cr[a] + r - 1e-5f);
                    }
                }
            }
            EXPECT_GE(children, 2) << "node " << i;
        }
        EXPECT_EQ(deepest, g.bvhDepth);
        EXPECT_GE(g.bvhDepth, 2);
        EXPECT_EQ(g.bvhStackSize(), (SNELL_BVH_WIDTH - 1) * g.bvhDepth);
        EXPECT_EQ(visited, g.nodes.size());
        for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(covered[k], 1) << k;
    }
}

}  // namespace
