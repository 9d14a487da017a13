// The scene's GPU layout: what the compute shader reads, prepared in double on
// the host. Coordinates are relative to an origin just in front of the nearest
// geometry along the view (primary rays start there), so a scene far from the
// eye, or a tiny one, keeps float precision at its own scale; true spheres are
// anchored surface points (shared_layout.h), only ellipsoids carry matrices;
// spheres are in BVH leaf order when a BVH is used. No Vulkan here.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "render/RenderRequest.h"
#include "scene/Parser.h"
#include "scene/Scene.h"
#include "shared_layout.h"

namespace snell::gpu {

static_assert(sizeof(Sphere) == 32 && offsetof(Sphere, normal) == 16);
static_assert(sizeof(Ellipsoid) == 48 && offsetof(Ellipsoid, row2) == 32);
static_assert(sizeof(Material) == 48 && offsetof(Material, kt) == 32);
static_assert(sizeof(Light) == 32 && offsetof(Light, colour) == 16);
static_assert(sizeof(BvhNode) == 16 * SNELL_BVH_NODE_TEXELS && offsetof(BvhNode, upperX) == 16 &&
              offsetof(BvhNode, child) == 96);
static_assert(sizeof(SphereBlock) == 32 * SNELL_BLOCK_SPHERES);
static_assert(offsetof(FrameParams, cornerDir) == 16 &&
              offsetof(FrameParams, radiance) == 96 && offsetof(FrameParams, imageWidth) == 128 &&
              offsetof(FrameParams, bvhNodeCount) == 152 && offsetof(FrameParams, sampleCount) == 160 &&
              offsetof(FrameParams, minWeight) == 172 && offsetof(FrameParams, airEta) == 184 &&
              offsetof(FrameParams, bvhAddressLow) == 188 && offsetof(FrameParams, rayStackAddressLow) == 196 &&
              offsetof(FrameParams, mediaStackAddressLow) == 204 && offsetof(FrameParams, reachInward) == 224 &&
              offsetof(FrameParams, lights) == 240 && sizeof(FrameParams) == 240 + 32 * SNELL_FRAME_LIGHTS);
static_assert(sizeof(TileParams) == 32 && offsetof(TileParams, resume) == 16 &&
              offsetof(TileParams, workgroupStride) == 20 && offsetof(TileParams, strideY) == 28);
static_assert(sizeof(SlotState) == 256 && offsetof(SlotState, sampleLight) == 192 && offsetof(SlotState, deferredLight) == 240 &&
              offsetof(SlotState, flaggedLow) == 224 && offsetof(SlotState, lost) == 32 && offsetof(SlotState, undecided) == 96 &&
              offsetof(SlotState, pixel) == 112 && offsetof(SlotState, finished) == 124 &&
              offsetof(SlotState, treeRays) == 128 && offsetof(SlotState, rays) == 136 &&
              offsetof(SlotState, frontierOld) == 152 && offsetof(SlotState, cutOff) == 160 &&
              offsetof(SlotState, settledWeight) == 176);
static_assert(sizeof(SphereReach) == 32 && offsetof(SphereReach, inward) == 16);
static_assert(sizeof(FlaggedSamples) == 32 && offsetof(FlaggedSamples, high) == 20);
static_assert(sizeof(OutputPixel) == 32 && offsetof(OutputPixel, estimate) == 16 &&
              offsetof(OutputPixel, report) == 20 && offsetof(OutputPixel, moved) == 28);
static_assert(sizeof(PendingRay) == 64 && offsetof(PendingRay, depth) == 48 && offsetof(PendingRay, resumeShading) == 60);
// An ellipsoid's index rides in a float (Sphere::anchorRadius.w), exact to the
// documented sphere limit.
static_assert(ParseLimits::kMaxSpheres < kMaxExactIndex);

// The shader's working precision for geometry (shaders/precision.glsl).
enum class Precision { Fp32, Fp64 };

// Spheres above this count are traversed through the BVH; fewer are tested in
// a loop. Measured by `snell bench` on lavapipe: with 10 glass spheres the BVH
// took 2.2× the loop's time, with 72 spheres 0.86×.
inline constexpr std::size_t kBvhThreshold = SNELL_MAX_UNROLLED_SPHERES;
// Whether to build and traverse a BVH: by that threshold, or forced (the bench).
enum class BvhMode { Auto, Off, On };
// How a BVH scene is searched: snell's own walk (physics/hit.glsl, traverseBvh), or
// the device's ray traversal (VK_KHR_ray_query over the spheres' boxes), or
// the device's where it is enabled (vk::ContextOptions::rayQueries).
enum class Traversal { Auto, Walk, RayQuery };

// A sphere's box as VkAabbPositionsKHR lays it out (6 floats).
struct SphereBox {
    float lower[3], upper[3];
};

struct GpuScene {
    std::vector<Sphere> spheres;
    std::vector<uint> sphereMaterials;
    std::vector<Ellipsoid> ellipsoids;
    std::vector<Material> materials;
    std::vector<Light> lights;
    std::vector<BvhNode> nodes;  // empty when no BVH is used
    // Each sphere's reach (render/Reach.h), rounded up to float; empty where
    // no sphere's is below R, and every ray's light is bounded by R.
    std::vector<SphereReach> reach;
    std::vector<bool> hollow;  // ReachBound::hollow, in the scene's order, for inwardHolds
    // With sphereBoxes asked for and a BVH: each sphere's box, in sphere
    // order, rounded outwards and padded for a float ray-box test.
    std::vector<SphereBox> sphereBoxes;
    // Fp64 only (else empty): the low parts of the float pairs hi + lo, in
    // the same layout (shared_layout.h); their non-geometric members are 0.
    std::vector<Sphere> sphereLows;
    std::vector<Ellipsoid> ellipsoidLows;
    std::vector<Light> lightLows;
    Precision precision = Precision::Fp32;
    std::size_t refractiveSpheres = 0;
    bool amplifying = false;
    bool traps = false;  // some material traps light (render/Truncation.h, growthTraps)
    snell::dvec3 eye{0.0};       // the camera's eye
    snell::dvec3 origin{0.0};    // the world point that is the origin on the GPU
    double primaryStart = 0.0;   // distance from the eye at which primary rays start
    double sphereExtent = 0.0;   // the farthest any true sphere's point lies from the origin
    int bvhDepth = 0;            // BVH nodes (of four children) on the longest root-to-leaf path
    // Entries the walk's stack needs: each node it enters leaves at most
    // all but one of its children waiting.
    int bvhStackSize() const { return std::max(1, (SNELL_BVH_WIDTH - 1) * bvhDepth); }
    double bvhBuildMs = 0.0;

    bool usesBvh() const { return !nodes.empty(); }
    // The lights are also in FrameParams.lights (SNELL_SPEC_LIGHTS_IN_FRAME).
    bool lightsInFrame() const { return lights.size() <= SNELL_FRAME_LIGHTS; }
    // Bytes of scene data the GPU holds (low parts included).
    std::size_t bytes() const;
};

GpuScene buildGpuScene(const snell::Scene& scene, const snell::Camera& camera,
                       Precision precision = Precision::Fp32, BvhMode bvh = BvhMode::Auto, bool sphereBoxes = false);

// How far primary rays from `eye` can go before they could meet any sphere.
double primaryStartDistance(const snell::Scene& scene, const snell::dvec3& eye);

// A device address as the two words GL_EXT_buffer_reference_uvec2 reads
// (FrameParams.bvhAddress, rayStackAddress, mediaStackAddress).
inline void splitAddress(std::uint64_t address, std::uint32_t& low, std::uint32_t& high) {
    low = static_cast<std::uint32_t>(address);
    high = static_cast<std::uint32_t>(address >> 32);
}

// The frame parameters of one render request (its camera, size, samples and
// trace settings); with `lowParts`, also the low parts of its float pairs (for
// the fp64 shader).
FrameParams makeFrameParams(const snell::Scene& scene, const GpuScene& gpuScene, const snell::RenderRequest& request,
                            FrameParams* lowParts = nullptr);

// A double as the float pair hi + lo: hi = float(v), lo = float(v − hi).
void splitDouble(double v, float& hi, float& lo);

}  // namespace snell::gpu
