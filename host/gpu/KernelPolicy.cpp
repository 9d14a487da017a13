#include "gpu/KernelPolicy.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "gpu/DriverProbe.h"

namespace snell::gpu {

bool choosesRayQueries(const vk::Context& context, RendererOptions& options) {
    if (options.precision == Precision::Fp64 && !context.float64Supported())
        throw vk::VulkanError("--precision fp64 needs shader doubles (the shaderFloat64 feature), which " +
                              std::string(context.properties().deviceName) +
                              " lacks; use --precision fp32, or another device (--gpu; lavapipe has them)");
    if (options.precision == Precision::Fp64 && !context.fp64Refusal().empty())
        throw vk::VulkanError("--precision fp64: " + context.fp64Refusal() +
                              "; use --precision fp32, --cpu (double precision), or lavapipe (--gpu)");
    if (options.traversal == Traversal::RayQuery) {
        if (options.precision == Precision::Fp64)
            throw vk::VulkanError("--traversal ray-query traces in fp32: it cannot be combined with --precision fp64");
        if (!context.rayQueriesEnabled())
            throw vk::VulkanError("--traversal ray-query: " + context.rayQueryAbsence() + "; use --traversal bvh");
        if (options.bvh == BvhMode::Auto) options.bvh = BvhMode::On;
    }
    // Auto takes the device's traversal on GPUs only: on lavapipe snell's walk
    // measured faster (docs/log/real-gpu.md, "The device's ray traversal").
    return options.precision == Precision::Fp32 && context.rayQueriesEnabled() &&
           (options.traversal == Traversal::RayQuery ||
            (options.traversal == Traversal::Auto && !context.isCpuDevice()));
}

KernelPolicy devicePolicy(vk::Context& context, const RendererOptions& options, const GpuScene& layout) {
    KernelPolicy policy;
    // Mesa 25's lavapipe calls a function for each texel fetch and checks
    // each lane's offset into a storage buffer against its size; its loads
    // and stores through a device address are faster, in the BVH walk and on
    // the ray and media stacks. Mesa 22.3 inlines its fetches and goes lane by
    // lane through an address (docs/log/bvh-walk.md, "The BVH as a storage
    // buffer", "The walk's floor", "The ray stack through its address").
    const bool addressesFaster = context.isLlvmpipe() && context.mesaMajor() >= 25;
    policy.bvhWords = options.readBvhWords.value_or(addressesFaster);
    policy.stacksByAddress = options.addressStacks.value_or(addressesFaster);
    // A CPU device runs a SIMD row's stores at per-lane indices lane by lane;
    // a GPU keeps such a stack in its local memory (unmeasured there: left
    // as it was). docs/log/bvh-walk.md, "The walk's stack in registers".
    policy.stackInRegisters = options.stackInRegisters.value_or(context.isCpuDevice()) && layout.usesBvh() &&
                              layout.bvhStackSize() <= SNELL_REGISTER_STACK_LIMIT;
    const std::uint32_t driverBudget = limitsLoopIterations(context) ? SNELL_LOOP_BUDGET_LIMITED : 0u;
    policy.loopBudget = options.loopBudget.value_or(driverBudget);
    policy.decisions = options.decisions;
    // A batch of shadow rays is numbered within 32 bits, min(4, 32 / subgroup
    // size) lights at a time: worth it for SIMD rows of up to 16 lanes. On a
    // CPU device only, where a subgroup's lanes run in lockstep: a GPU's would
    // also need to meet at a subgroup barrier before they read each other's
    // hits, and it is unmeasured there (docs/log/bvh-walk.md, "Shadow rays
    // shared out"). Only with snell's own walk and more than one light (one
    // shadow ray a lane has no one to share with), and where the walk cannot
    // be suspended (the shadow rays of a batch are walked in one loop).
    const bool deviceShares =
        context.isCpuDevice() && context.subgroupSize() >= 2 && context.subgroupSize() <= 16;
    policy.sharesShadowRays = options.shareShadowRays && deviceShares && layout.usesBvh() &&
                              layout.lights.size() > 1 && layout.sphereBoxes.empty() && policy.loopBudget == 0u;
    policy.spheresInBlock = !layout.usesBvh() && layout.spheres.size() <= SNELL_BLOCK_SPHERES;
    policy.planForCpu = context.isCpuDevice() && !options.planAsGpu;
    policy.countLanes = options.countLanes;
    return policy;
}

namespace {

// How many rays may wait on an invocation's stack (schedule/tree.glsl, followChildren).
// A ray waits only where a hit both reflects and refracts, and then the
// lighter child goes on: below k waiting rays the path's weight is at most
// q^k, q the largest gain of a lighter child (min(max ks, max kt) over the
// materials), times gains of at most g = max(ks + kt) elsewhere. Where g <= 1
// and q < 1 the weight must stay above the cut-off floor w, so k <= log w /
// log q: 16 for the GPU's floor 1e-5 and glass of ks 0.5, however deep the tree,
// and a chain of reflections needs none. Otherwise (amplifying materials, no
// cut-off) the depth limit bounds k, up to kMaxRayStack; past that the
// shader drops the child that would wait and counts it (SNELL_COUNTER_OVERFLOW).
constexpr std::uint32_t kMaxRayStack = 256;

// Frontier entries an invocation keeps (schedule/frontier.glsl, deferRay). On a CPU device
// there are few invocations (a few workgroups a core) and room for many; a GPU
// needs its invocations more than long frontiers, except in a scene with
// traps, whose pixels go on below the floor from what waits there: a ray
// lost to a full frontier may be light that would have grown. At 32 entries
// glass-in-water-gap-0 at 128² lost the light of 87 pixels (off by up to
// 207/255 where the reference saturates); at 512 its image agrees with the
// reference, though 811 of its pixels still lose rays under the floor there.
// The longer frontier makes the loss rarer; it does not end it: such a pixel
// claims no estimate of its error (schedule/steps.glsl, finishPixel).
constexpr std::uint32_t kCpuFrontier = 512;
constexpr std::uint32_t kGpuFrontier = 32;
std::uint32_t rayStackEntries(const Scene& scene, const TraceSettings& trace, bool reflection) {
    if (!reflection) return 0;
    double lighter = 0.0, gain = 0.0;
    for (const snell::Material& m : scene.materials) {
        const double ks = std::max({m.ks.x, m.ks.y, m.ks.z}), kt = std::max({m.kt.x, m.kt.y, m.kt.z});
        if (ks > 0.0 && kt > 0.0) lighter = std::max(lighter, std::min(ks, kt));
        gain = std::max(gain, m.largestGain());
    }
    const auto depthBound = static_cast<std::uint32_t>(std::clamp(trace.maxDepth, 0, int(kMaxRayStack)));
    if (lighter == 0.0) return 0;
    if (gain > 1.0 || lighter >= 1.0 || trace.minWeight <= 0.0) return depthBound;
    const double k = std::floor(std::log(trace.minWeight) / std::log(lighter)) + 1.0;  // + 1: float rounding
    return std::min(depthBound, static_cast<std::uint32_t>(std::min(k, double(kMaxRayStack))));
}

// The constants that say what the scene holds and how the kernel reads it.
void specialiseToScene(const GpuScene& layout, const KernelPolicy& policy, Specialisation& values) {
    values[SNELL_SPEC_USE_BVH] = layout.usesBvh();
    values[SNELL_SPEC_BVH_WORDS] = layout.usesBvh() && policy.bvhWords;
    const bool unrolled = !layout.usesBvh() && layout.spheres.size() <= SNELL_MAX_UNROLLED_SPHERES;
    values[SNELL_SPEC_SPHERE_COUNT] = unrolled ? static_cast<std::uint32_t>(layout.spheres.size()) : 0u;
    values[SNELL_SPEC_SPHERES_IN_BLOCK] = policy.spheresInBlock;
    if (unrolled)
        for (std::size_t i = 0; i < layout.spheres.size(); ++i)
            if (layout.spheres[i].anchorRadius.w < 0.0f) values[SNELL_SPEC_ELLIPSOID_MASK] |= 1u << i;
    values[SNELL_SPEC_BVH_DEPTH] = static_cast<std::uint32_t>(layout.bvhStackSize());
    values[SNELL_SPEC_STACK_IN_REGISTERS] = policy.stackInRegisters;
    values[SNELL_SPEC_SHARE_SHADOW_RAYS] = policy.sharesShadowRays;
    values[SNELL_SPEC_LIGHTS_IN_FRAME] = layout.lightsInFrame();
    values[SNELL_SPEC_STACKS_BY_ADDRESS] = policy.stacksByAddress;
    values[SNELL_SPEC_DECISIONS] = policy.decisions;
    values[SNELL_SPEC_HAS_ELLIPSOIDS] = !layout.ellipsoids.empty();
    values[SNELL_SPEC_HAS_LIGHTS] = !layout.lights.empty();
    values[SNELL_SPEC_MAX_MEDIA] = static_cast<std::uint32_t>(
        std::clamp<std::size_t>(layout.refractiveSpheres, 1, SNELL_MAX_MEDIA_LIMIT));
    values[SNELL_SPEC_AMPLIFYING] = layout.amplifying;
    values[SNELL_SPEC_TRAPS] = layout.traps;
    values[SNELL_SPEC_REACH] = !layout.reach.empty();
}

}  // namespace

Specialisation specialise(const Scene& scene, const GpuScene& layout, const KernelPolicy& policy,
                          const RenderRequest& request, bool countRays) {
    // Specialise to the scene: only what it uses is compiled.
    const bool hasRefraction = layout.refractiveSpheres > 0 && request.trace.refraction;
    const bool hasReflection = scene.anyReflection() && request.trace.reflection;
    Specialisation values{};
    specialiseToScene(layout, policy, values);
    values[SNELL_SPEC_HAS_REFRACTION] = hasRefraction;
    values[SNELL_SPEC_HAS_REFLECTION] = hasReflection;
    values[SNELL_SPEC_SHADOWS] = request.trace.shadows;
    values[SNELL_SPEC_COUNT_RAYS] = countRays;
    // Without refraction a ray has at most one child, traced at once: only a
    // suspended ray ever waits. With it, see rayStackEntries.
    values[SNELL_SPEC_RAY_STACK] =
        hasRefraction ? rayStackEntries(scene, request.trace, hasReflection) + 1 : 1;  // + the suspended ray
    // Where ray trees diverge (refraction, a BVH) a workgroup whose share of
    // the tile is taken helps with the others' (schedule/pixels.glsl, takePixel); on
    // cheap, even scenes that cost more than it won (docs/log/lane-occupancy.md, "Help with the other shares").
    values[SNELL_SPEC_HELPS] = hasRefraction || layout.usesBvh();
    // Under a tolerance, a frontier for the rays a step leaves under its
    // cut-off; where it is full, rays are traced down to the floor instead.
    const bool secondaryRays = hasRefraction || hasReflection;
    values[SNELL_SPEC_FRONTIER] =
        request.trace.tolerance > 0.0 && secondaryRays
            ? (policy.planForCpu || layout.traps ? kCpuFrontier : kGpuFrontier)
            : 0u;
    values[SNELL_SPEC_LOOP_BUDGET] = policy.loopBudget;
    values[SNELL_SPEC_COUNT_LANES] = policy.countLanes;
    // (Whether or not this request re-traces: its cost probe shares the pipeline.)
    const int samples = request.samplesTraced();
    values[SNELL_SPEC_BY_SAMPLE] = policy.decisions && !layout.amplifying && samples > 1 && samples <= 64;
    return values;
}

}  // namespace snell::gpu
