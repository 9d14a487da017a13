#include "gpu/ComputeRenderer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <thread>

#include "common/Clock.h"
#include "gpu/DriverProbe.h"
#include "render/WorkgroupSchedule.h"
#include "vulkan/SpecialisedModule.h"
#include "trace_comp_spv.h"       // generated at build time from shaders/trace.comp
#include "trace_fp64_comp_spv.h"  // the same, compiled with SNELL_FP64
#include "trace_ray_query_comp_spv.h"  // the same, compiled with SNELL_RAY_QUERY

namespace snell {

using vk::check;

namespace {


constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
// The ray and media stacks, read as storage buffers or through their addresses
// (SNELL_SPEC_STACKS_BY_ADDRESS).
constexpr VkBufferUsageFlags kStack = kStorage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

// The descriptor type of each binding of shared_layout.h.
VkDescriptorType descriptorType(std::uint32_t binding) {
    switch (binding) {
    case SNELL_BINDING_FRAME:
    case SNELL_BINDING_FRAME_LOW:
    case SNELL_BINDING_SPHERE_BLOCK: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    case SNELL_BINDING_SPHERES:
    case SNELL_BINDING_SPHERE_MATERIALS:
    case SNELL_BINDING_ELLIPSOIDS:
    case SNELL_BINDING_MATERIALS:
    case SNELL_BINDING_LIGHTS:
    case SNELL_BINDING_BVH:
    case SNELL_BINDING_SPHERES_LOW:
    case SNELL_BINDING_ELLIPSOIDS_LOW:
    case SNELL_BINDING_LIGHTS_LOW: return VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    case SNELL_BINDING_ACCELERATION: return VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    default: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    }
}

}  // namespace

struct ComputeRenderer::Pipeline {
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    vk::ComputeShader shader;  // instead of the pipeline, where the device has shader objects
    VkShaderModule module = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;
    VkCommandPool commandPool = VK_NULL_HANDLE;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    vk::Buffer frame, counters, output, slotStates, rayStack, mediaStack;
    vk::Buffer frameLow, rayStackLow;  // fp64 only
    std::uint32_t rayEntries = 1;     // the RAY_STACK and FRONTIER specialisations: an invocation's entries
    std::uint32_t maxMedia = 1;       // the MAX_MEDIA specialisation
    bool folded = false;              // the module has the specialisation folded in (vulkan/SpecialisedModule.h)
    std::vector<std::uint32_t> bindings;  // the shader's, in order
    // What it was built for: kept between renders and reused while these match.
    Specialisation values{};
    // What its buffers hold: reused by renders that need no more (the preview
    // alternates sizes while the camera moves).
    VkDeviceSize tilePixels = 0;
    VkDeviceSize slots = 0;  // persistent invocations
};

ComputeRenderer::ComputeRenderer(vk::Context& context, const Scene& scene, const Camera& camera,
                                 gpu::Precision precision, gpu::BvhMode bvh, gpu::Traversal traversal)
    : context_(context), scene_(scene) {
    if (precision == gpu::Precision::Fp64 && !context.float64Supported())
        throw vk::VulkanError("--precision fp64 needs shader doubles (the shaderFloat64 feature), which " +
                              std::string(context.properties().deviceName) +
                              " lacks; use --precision fp32, or another device (--gpu; lavapipe has them)");
    if (precision == gpu::Precision::Fp64 && !context.fp64Refusal().empty())
        throw vk::VulkanError("--precision fp64: " + context.fp64Refusal() +
                              "; use --precision fp32, --cpu (double precision), or lavapipe (--gpu)");
    if (traversal == gpu::Traversal::RayQuery) {
        if (precision == gpu::Precision::Fp64)
            throw vk::VulkanError("--traversal ray-query traces in fp32: it cannot be combined with --precision fp64");
        if (!context.rayQueriesEnabled())
            throw vk::VulkanError("--traversal ray-query: " + context.rayQueryAbsence() + "; use --traversal bvh");
        if (bvh == gpu::BvhMode::Auto) bvh = gpu::BvhMode::On;
    }
    // Auto takes the device's traversal on GPUs only: on lavapipe snell's walk
    // measured faster (docs/performance.md, "The device's ray traversal").
    const bool rayQuery = precision == gpu::Precision::Fp32 && context.rayQueriesEnabled() &&
                          (traversal == gpu::Traversal::RayQuery ||
                           (traversal == gpu::Traversal::Auto && !context.isCpuDevice()));
    const auto start = Clock::now();
    layout_ = gpu::buildGpuScene(scene, camera, precision, bvh, rayQuery);
    // Mesa 25's lavapipe calls a function for each texel fetch and checks
    // each lane's offset into a storage buffer against its size; its loads
    // and stores through a device address are faster, in the BVH walk and on
    // the ray and media stacks. Mesa 22.3 inlines its fetches and goes lane by
    // lane through an address (docs/performance.md, "The BVH as a storage
    // buffer", "The walk's floor", "The ray stack through its address").
    const bool addressesFaster = context.isLlvmpipe() && context.mesaMajor() >= 25;
    bvhWords_ = addressesFaster;
    stacksByAddress_ = addressesFaster;
    // A CPU device runs a SIMD row's stores at per-lane indices lane by lane;
    // a GPU keeps such a stack in its local memory (unmeasured there: left
    // as it was). docs/performance.md, "The walk's stack in registers".
    stackInRegisters_ = context.isCpuDevice();
    // A batch of shadow rays is numbered within 32 bits, min(4, 32 / subgroup
    // size) lights at a time: worth it for SIMD rows of up to 16 lanes. On a
    // CPU device only, where a subgroup's lanes run in lockstep: a GPU's would
    // also need to meet at a subgroup barrier before they read each other's
    // hits, and it is unmeasured there (docs/performance.md, "Shadow rays
    // shared out").
    deviceSharesShadowRays_ = context.isCpuDevice() && context.subgroupSize() >= 2 && context.subgroupSize() <= 16;
    loopBudget_ = limitsLoopIterations(context) ? SNELL_LOOP_BUDGET_LIMITED : 0u;
    // Each scene array becomes a texel buffer (shared_layout.h): its structs
    // are runs of texels, every view RGBA32UI, floats by their bits (lavapipe
    // compiles its fetch functions for each new format a view has).
    const VkDeviceSize maxTexels = context.properties().limits.maxTexelBufferElements;
    auto upload = [&](std::uint32_t binding, const auto& v, const char* what, VkBufferUsageFlags alsoAs = 0) {
        const VkDeviceSize bytes = v.size() * sizeof(v[0]);
        const VkDeviceSize texelBytes = 16;
        if (bytes / texelBytes > maxTexels)
            throw vk::VulkanError(std::string("the scene's ") + what + " need " + std::to_string(bytes / texelBytes) +
                                  " texels, more than this device's texel-buffer limit of " +
                                  std::to_string(maxTexels));
        sceneBuffers_[binding] =
            context_.createBufferWithData(v.data(), bytes, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | alsoAs);
        VkBufferViewCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
        info.buffer = sceneBuffers_[binding].buffer;
        info.format = VK_FORMAT_R32G32B32A32_UINT;
        info.range = VK_WHOLE_SIZE;
        check(vkCreateBufferView(context_.device(), &info, nullptr, &sceneViews_[binding]), "vkCreateBufferView");
    };
    try {
        // The spheres' materials four a texel.
        std::vector<std::uint32_t> sphereMaterials = layout_.sphereMaterials;
        sphereMaterials.resize((sphereMaterials.size() + 3) / 4 * 4);
        upload(SNELL_BINDING_SPHERES, layout_.spheres, "spheres");
        upload(SNELL_BINDING_SPHERE_MATERIALS, sphereMaterials, "spheres");
        upload(SNELL_BINDING_ELLIPSOIDS, layout_.ellipsoids, "ellipsoids");
        upload(SNELL_BINDING_MATERIALS, layout_.materials, "materials");
        upload(SNELL_BINDING_LIGHTS, layout_.lights, "lights");
        // Read as texels, or through its device address (FrameParams.bvhAddress).
        upload(SNELL_BINDING_BVH, layout_.nodes, "BVH nodes", VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
        if (!layout_.sphereBoxes.empty())
            sphereBoxes_ = std::make_unique<vk::BoxAccelerationStructure>(
                context_, layout_.sphereBoxes.data(), static_cast<std::uint32_t>(layout_.sphereBoxes.size()));
        // Small scenes: the spheres again, as a uniform block (shared_layout.h);
        // for fp64 their low parts follow in the same buffer.
        std::vector<gpu::SphereBlock> blocks(2);
        if (spheresInBlock()) {
            std::copy(layout_.spheres.begin(), layout_.spheres.end(), blocks[0].spheres);
            std::copy(layout_.sphereLows.begin(), layout_.sphereLows.end(), blocks[1].spheres);
        }
        const std::size_t blockBytes = (precision == gpu::Precision::Fp64 ? 2 : 1) * sizeof(gpu::SphereBlock);
        sceneBuffers_[SNELL_BINDING_SPHERE_BLOCK] =
            context_.createBufferWithData(blocks.data(), blockBytes, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
        if (precision == gpu::Precision::Fp64) {
            upload(SNELL_BINDING_SPHERES_LOW, layout_.sphereLows, "spheres");
            upload(SNELL_BINDING_ELLIPSOIDS_LOW, layout_.ellipsoidLows, "ellipsoids");
            upload(SNELL_BINDING_LIGHTS_LOW, layout_.lightLows, "lights");
        }
    } catch (...) {
        destroyBuffers();
        throw;
    }
    uploadMs_ = msSince(start);
}

bool ComputeRenderer::stackInRegisters() const {
    return stackInRegisters_ && layout_.usesBvh() && layout_.bvhStackSize() <= SNELL_REGISTER_STACK_LIMIT;
}

bool ComputeRenderer::sharesShadowRays() const {
    // Only with snell's own walk and more than one light (one shadow ray a
    // lane has no one to share with), and where the walk cannot be suspended
    // (the shadow rays of a batch are walked in one loop).
    return shareShadowRays_ && deviceSharesShadowRays_ && layout_.usesBvh() && layout_.lights.size() > 1 &&
           !sphereBoxes_ && loopBudget_ == 0u;
}

const char* ComputeRenderer::traversal() const {
    return sphereBoxes_ ? "ray-query" : layout_.usesBvh() ? "bvh" : "loop";
}

bool ComputeRenderer::spheresInBlock() const {
    return !layout_.usesBvh() && layout_.spheres.size() <= SNELL_BLOCK_SPHERES;
}

ComputeRenderer::~ComputeRenderer() {
    if (cached_) destroyPipeline(*cached_);
    destroyBuffers();
}

void ComputeRenderer::destroyBuffers() {
    sphereBoxes_.reset();
    for (VkBufferView& v : sceneViews_) {
        if (v) vkDestroyBufferView(context_.device(), v, nullptr);
        v = VK_NULL_HANDLE;
    }
    for (vk::Buffer& b : sceneBuffers_) context_.destroy(b);
}

namespace {

// How many rays may wait on an invocation's stack (trace.comp, spawnChildren).
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

// Frontier entries an invocation keeps (trace.comp, deferRay). On a CPU device
// there are few invocations (a few workgroups a core) and room for many; a GPU
// needs its invocations more than long frontiers, except in a scene with
// traps, whose pixels go on below the floor from what waits there: a ray
// lost to a full frontier may be light that would have grown. At 32 entries
// glass-in-water-gap-0 at 128² lost the light of 87 pixels (off by up to
// 207/255 where the reference saturates); at 512 its image agrees with the
// reference, though 811 of its pixels still lose rays under the floor there.
// The longer frontier makes the loss rarer; it does not end it: such a pixel
// claims no estimate of its error (trace.comp, finishPixel).
constexpr std::uint32_t kCpuFrontier = 512;
constexpr std::uint32_t kGpuFrontier = 32;
std::uint32_t rayStackEntries(const Scene& scene, const TraceSettings& trace, bool reflection) {
    if (!reflection) return 0;
    double lighter = 0.0, gain = 0.0;
    for (const Material& m : scene.materials) {
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

}  // namespace

ComputeRenderer::Specialisation ComputeRenderer::specialise(const RenderRequest& request, bool countRays) const {
    // Specialise to the scene: only what it uses is compiled.
    const bool hasRefraction = layout_.refractiveSpheres > 0 && request.trace.refraction;
    const bool hasReflection = scene_.anyReflection() && request.trace.reflection;
    Specialisation values{};
    values[SNELL_SPEC_USE_BVH] = layout_.usesBvh();
    values[SNELL_SPEC_BVH_WORDS] = layout_.usesBvh() && bvhWords_;
    const bool unrolled = !layout_.usesBvh() && layout_.spheres.size() <= SNELL_MAX_UNROLLED_SPHERES;
    values[SNELL_SPEC_SPHERE_COUNT] = unrolled ? static_cast<std::uint32_t>(layout_.spheres.size()) : 0u;
    values[SNELL_SPEC_SPHERES_IN_BLOCK] = spheresInBlock();
    if (unrolled)
        for (std::size_t i = 0; i < layout_.spheres.size(); ++i)
            if (layout_.spheres[i].anchorRadius.w < 0.0f) values[SNELL_SPEC_ELLIPSOID_MASK] |= 1u << i;
    values[SNELL_SPEC_BVH_DEPTH] = static_cast<std::uint32_t>(layout_.bvhStackSize());
    values[SNELL_SPEC_STACK_IN_REGISTERS] = stackInRegisters();
    values[SNELL_SPEC_SHARE_SHADOW_RAYS] = sharesShadowRays();
    values[SNELL_SPEC_LIGHTS_IN_FRAME] = layout_.lightsInFrame();
    values[SNELL_SPEC_STACKS_BY_ADDRESS] = stacksByAddress_;
    values[SNELL_SPEC_HAS_ELLIPSOIDS] = !layout_.ellipsoids.empty();
    values[SNELL_SPEC_HAS_REFRACTION] = hasRefraction;
    values[SNELL_SPEC_HAS_REFLECTION] = hasReflection;
    values[SNELL_SPEC_SHADOWS] = request.trace.shadows;
    values[SNELL_SPEC_HAS_LIGHTS] = !layout_.lights.empty();
    values[SNELL_SPEC_COUNT_RAYS] = countRays;
    values[SNELL_SPEC_MAX_MEDIA] = static_cast<std::uint32_t>(
        std::clamp<std::size_t>(layout_.refractiveSpheres, 1, SNELL_MAX_MEDIA_LIMIT));
    // Without refraction a ray has at most one child, traced at once: only a
    // suspended ray ever waits. With it, see rayStackEntries.
    values[SNELL_SPEC_RAY_STACK] =
        hasRefraction ? rayStackEntries(scene_, request.trace, hasReflection) + 1 : 1;  // + the suspended ray
    values[SNELL_SPEC_AMPLIFYING] = layout_.amplifying;
    values[SNELL_SPEC_TRAPS] = layout_.traps;
    // Where ray trees diverge (refraction, a BVH) a workgroup whose share of
    // the tile is taken helps with the others' (trace.comp, takePixel); on
    // cheap, even scenes that cost more than it won (docs/performance.md).
    values[SNELL_SPEC_HELPS] = hasRefraction || layout_.usesBvh();
    // Under a tolerance, a frontier for the rays a step leaves under its
    // cut-off; where it is full, rays are traced down to the floor instead.
    const bool secondaryRays = hasRefraction || hasReflection;
    values[SNELL_SPEC_FRONTIER] =
        request.trace.tolerance > 0.0 && secondaryRays
            ? (plansForCpu() || layout_.traps ? kCpuFrontier : kGpuFrontier)
            : 0u;
    values[SNELL_SPEC_LOOP_BUDGET] = loopBudget_;
    values[SNELL_SPEC_COUNT_LANES] = countLanes_;
    return values;
}

// The kernel alone, for p's module, layout and specialisation: a shader
// object from its kept binary where the device has them and the run keeps a
// cache, else a pipeline.
void ComputeRenderer::createKernel(Pipeline& p, std::span<const std::uint32_t> code) {
    std::array<VkSpecializationMapEntry, SNELL_SPEC_COUNT> entries{};
    for (std::uint32_t i = 0; i < entries.size(); ++i)
        entries[i] = {i, i * static_cast<std::uint32_t>(sizeof(std::uint32_t)), sizeof(std::uint32_t)};
    VkSpecializationInfo spec{static_cast<std::uint32_t>(entries.size()), entries.data(),
                              p.values.size() * sizeof(std::uint32_t), p.values.data()};
    const vk::ShaderObjects& objects = context_.shaderObjects();
    const std::string cacheDirectory = context_.cacheDirectory();
    if (objects.enabled && useShaderObjects_ && !cacheDirectory.empty()) {
        std::vector<std::uint32_t> layoutWords;
        for (std::uint32_t binding : p.bindings) {
            layoutWords.push_back(binding);
            layoutWords.push_back(std::uint32_t(descriptorType(binding)));
        }
        vk::ComputeShaderInfo info;
        info.spirv = code;
        info.setLayout = p.setLayout;
        info.setLayoutWords = layoutWords;
        info.pushConstants = {VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::TileParams)};
        info.specialisation = p.folded ? nullptr : &spec;
        info.specialisationWords = p.values;
        p.shader = vk::createComputeShader(context_.device(), objects, info, cacheDirectory);
        return;
    }
    VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    moduleInfo.codeSize = code.size_bytes();
    moduleInfo.pCode = code.data();
    check(vkCreateShaderModule(context_.device(), &moduleInfo, nullptr, &p.module), "vkCreateShaderModule");
    VkComputePipelineCreateInfo pipelineInfo{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pipelineInfo.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipelineInfo.stage.module = p.module;
    pipelineInfo.stage.pName = "main";
    pipelineInfo.stage.pSpecializationInfo = p.folded ? nullptr : &spec;
    pipelineInfo.layout = p.layout;
    check(vkCreateComputePipelines(context_.device(), context_.pipelineCache(), 1, &pipelineInfo, nullptr,
                                   &p.pipeline),
          "vkCreateComputePipelines");
}

void ComputeRenderer::createPipeline(const Specialisation& values, Pipeline& p) {
    VkDevice device = context_.device();
    p.values = values;
    const bool wide = layout_.precision == gpu::Precision::Fp64;
    // The fp32 shader's bindings; fp64 adds the low parts, ray queries the acceleration structure.
    p.bindings.clear();
    for (std::uint32_t i = 0; i < (wide ? SNELL_BINDING_COUNT : SNELL_BINDING_COUNT_FP32); ++i) p.bindings.push_back(i);
    if (sphereBoxes_) p.bindings.push_back(SNELL_BINDING_ACCELERATION);
    std::vector<VkDescriptorSetLayoutBinding> bindings(p.bindings.size());
    for (std::size_t k = 0; k < bindings.size(); ++k) {
        bindings[k].binding = p.bindings[k];
        bindings[k].descriptorCount = 1;
        bindings[k].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        bindings[k].descriptorType = descriptorType(p.bindings[k]);
    }
    VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    setInfo.bindingCount = static_cast<std::uint32_t>(bindings.size());
    setInfo.pBindings = bindings.data();
    check(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &p.setLayout), "vkCreateDescriptorSetLayout");

    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::TileParams)};
    VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &p.setLayout;
    layoutInfo.pushConstantRangeCount = 1;
    layoutInfo.pPushConstantRanges = &push;
    check(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &p.layout), "vkCreatePipelineLayout");

    using Words = std::span<const std::uint32_t>;
    const Words compiled = wide           ? Words(snell_trace_fp64_comp_spv)
                           : sphereBoxes_ ? Words(snell_trace_ray_query_comp_spv)
                                          : Words(snell_trace_comp_spv);
    const std::vector<std::uint32_t> folded =
        foldSpecialisation_ ? vk::specialisedModule(compiled, values, context_.cacheDirectory())
                            : std::vector<std::uint32_t>();
    p.folded = !folded.empty();
    p.rayEntries = values[SNELL_SPEC_RAY_STACK] + values[SNELL_SPEC_FRONTIER];
    p.maxMedia = values[SNELL_SPEC_MAX_MEDIA];
    createKernel(p, p.folded ? Words(folded) : compiled);

    std::vector<VkDescriptorPoolSize> sizes;
    for (std::uint32_t binding : p.bindings) {
        const VkDescriptorType type = descriptorType(binding);
        auto size = std::find_if(sizes.begin(), sizes.end(), [&](const VkDescriptorPoolSize& s) { return s.type == type; });
        if (size == sizes.end()) sizes.push_back({type, 1});
        else ++size->descriptorCount;
    }
    VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    poolInfo.maxSets = 1;
    poolInfo.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
    poolInfo.pPoolSizes = sizes.data();
    check(vkCreateDescriptorPool(device, &poolInfo, nullptr, &p.pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = p.pool;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &p.setLayout;
    check(vkAllocateDescriptorSets(device, &alloc, &p.set), "vkAllocateDescriptorSets");

    VkCommandPoolCreateInfo cpInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cpInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cpInfo.queueFamilyIndex = context_.queueFamily();
    check(vkCreateCommandPool(device, &cpInfo, nullptr, &p.commandPool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo cbInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cbInfo.commandPool = p.commandPool;
    cbInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbInfo.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(device, &cbInfo, &p.commands), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(device, &fenceInfo, nullptr, &p.fence), "vkCreateFence");
    if (context_.timestampsSupported()) {
        VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        q.queryType = VK_QUERY_TYPE_TIMESTAMP;
        q.queryCount = 2;
        check(vkCreateQueryPool(device, &q, nullptr, &p.queries), "vkCreateQueryPool");
    }
}

void ComputeRenderer::destroyPipeline(Pipeline& p) {
    VkDevice device = context_.device();
    vkDeviceWaitIdle(device);
    if (p.queries) vkDestroyQueryPool(device, p.queries, nullptr);
    if (p.fence) vkDestroyFence(device, p.fence, nullptr);
    if (p.commandPool) vkDestroyCommandPool(device, p.commandPool, nullptr);
    if (p.pool) vkDestroyDescriptorPool(device, p.pool, nullptr);
    if (p.pipeline) vkDestroyPipeline(device, p.pipeline, nullptr);
    if (p.shader.shader) context_.shaderObjects().destroy(device, p.shader.shader, nullptr);
    if (p.module) vkDestroyShaderModule(device, p.module, nullptr);
    if (p.layout) vkDestroyPipelineLayout(device, p.layout, nullptr);
    if (p.setLayout) vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
    context_.destroy(p.frame);
    context_.destroy(p.counters);
    context_.destroy(p.output);
    context_.destroy(p.slotStates);
    context_.destroy(p.rayStack);
    context_.destroy(p.mediaStack);
    context_.destroy(p.frameLow);
    context_.destroy(p.rayStackLow);
}

namespace {

void memoryBarrier(VkCommandBuffer cmd, VkAccessFlags srcAccess, VkAccessFlags dstAccess, VkPipelineStageFlags srcStage,
                   VkPipelineStageFlags dstStage) {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 1, &b, 0, nullptr, 0, nullptr);
}

// The dispatch's counters, then each workgroup's, then the bits of the
// shares with pixels left and those of their words (shared_layout.h).
std::size_t shareBitsAt(std::uint64_t workgroups) { return SNELL_SHARE_BITS_AT(workgroups); }
std::size_t shareWords(std::uint64_t workgroups) { return SNELL_SHARE_WORDS(workgroups); }
std::size_t wordBitsAt(std::uint64_t workgroups) { return SNELL_WORD_BITS_AT(workgroups); }
std::size_t counterCount(std::uint64_t workgroups) { return SNELL_COUNTERS_FOR(workgroups); }
// Bits 0..n-1 set in words from counters[at] on.
void setBits(std::uint32_t* counters, std::size_t at, std::uint64_t n) {
    for (std::uint64_t i = 0; i < n; i += 32) counters[at + i / 32] = n - i >= 32 ? ~0u : (1u << (n - i)) - 1u;
}

// Device memory for the invocations' ray stacks: 64 MiB on a CPU device; on
// a GPU a sixteenth of its memory, up to 1 GiB, for up to kGpuInvocations
// invocations. On an H200 at 2048², 64 MiB left SphereFlake2 (8.5 KB of
// stack an invocation at --depth 64) 7 872 invocations and took 1590 ms,
// 1 GiB 126 336 and 735 ms; showcase took 42 ms with 2^18 invocations and
// 212 with a million (every pixel of the tile its own), tir 78 and 344.
// 2^18 fills an H200 (132 multiprocessors of 2048 threads). (Where it
// lost: scenes/glass 20.7 → 38.2 ms with 13 000 → 210 000; docs/performance.md.)
constexpr VkDeviceSize kStackBudget = 64ull << 20;
constexpr VkDeviceSize kGpuStackBudget = 1ull << 30;
constexpr VkDeviceSize kGpuInvocations = 1ull << 18;
// Workgroups of persistent invocations per core on a CPU device (lavapipe):
// enough that the cores finish together.
constexpr unsigned kCpuWorkgroupsPerCore = 8;

// The image's column and row of the tile's column x and row y (TileParams;
// trace.comp, imagePixel).
int imageColumn(const gpu::TileParams& tile, std::uint32_t x) {
    const std::uint32_t run = SNELL_TILE_COLUMN_RUN, inRun = x % run;
    return int(tile.originX + (x - inRun) * tile.strideX + inRun);
}
int imageRow(const gpu::TileParams& tile, std::uint32_t y) {
    const std::uint32_t run = SNELL_TILE_ROW_RUN, inRun = y % run;
    return int(tile.originY + (y - inRun) * tile.strideY + inRun);
}
// Of `size` columns (rows) dealt in runs of `run` to `tiles` tiles in turn,
// those of tile `t`: `run` of each full round, then what the last round
// leaves for its run.
int dealtTo(int t, int tiles, int size, int run) {
    const int round = run * tiles;
    return size / round * run + std::clamp(size % round - t * run, 0, run);
}

}  // namespace

// How render() covers its window: tiles of at most kMaxTileSide² pixels (16
// MiB of float image), each traced by the same persistent invocations;
// interleaved up to kMaxInterleavedSide, else blocks.
struct ComputeRenderer::TilePlan {
    PixelWindow area;  // the window rendered; pixel coordinates stay the whole image's
    int tileWidth = 0, tileHeight = 0, tilesX = 0, tilesY = 0;  // the largest tile's size
    bool interleaved = false;  // tile (i, j): every tilesX-th run of columns from run i, and so rows (TileParams)
    VkDeviceSize invocations = 0;
    std::uint32_t workgroupStride = 1;  // TileParams::workgroupStride
    // Whether workgroups help with each other's shares once theirs is taken
    // (SNELL_SPEC_HELPS): then what a workgroup finished is not its share's.
    bool helps = false;

    TilePlan(const PixelWindow& window, bool interleave) : area(window) {
        tilesX = (area.width() + kMaxTileSide - 1) / kMaxTileSide;
        tilesY = (area.height() + kMaxTileSide - 1) / kMaxTileSide;
        interleaved = interleave && interleaves(area);
        tileWidth = interleaved ? tile(0, 0).width : std::min(kMaxTileSide, area.width());
        tileHeight = interleaved ? tile(0, 0).height : std::min(kMaxTileSide, area.height());
    }
    int count() const { return tilesX * tilesY; }
    // The rows streamed at a time: a row of blocks, or the whole of interleaved tiles.
    int bandRows() const { return interleaved ? area.height() : tileHeight; }
    std::uint64_t workgroups() const { return invocations / SNELL_WORKGROUP_SIZE; }
    // The share of the tile's pixels workgroup w takes (trace.comp, takePixel).
    std::uint64_t shareOf(std::uint64_t w) const { return w * workgroupStride % workgroups(); }
    VkDeviceSize tilePixels() const { return VkDeviceSize(tileWidth) * tileHeight; }
    // Tile (tx, ty): where it is, and how an invocation steps through it.
    gpu::TileParams tile(int tx, int ty) const {
        gpu::TileParams t{};
        if (interleaved) {
            t.originX = std::uint32_t(area.x0 + tx * SNELL_TILE_COLUMN_RUN);
            t.originY = std::uint32_t(area.y0 + ty * SNELL_TILE_ROW_RUN);
            t.width = std::uint32_t(dealtTo(tx, tilesX, area.width(), SNELL_TILE_COLUMN_RUN));
            t.height = std::uint32_t(dealtTo(ty, tilesY, area.height(), SNELL_TILE_ROW_RUN));
            t.strideX = std::uint32_t(tilesX);
            t.strideY = std::uint32_t(tilesY);
        } else {
            t.originX = std::uint32_t(area.x0 + tx * tileWidth);
            t.originY = std::uint32_t(area.y0 + ty * tileHeight);
            t.width = std::uint32_t(std::min(tileWidth, area.width() - tx * tileWidth));
            t.height = std::uint32_t(std::min(tileHeight, area.height() - ty * tileHeight));
            t.strideX = t.strideY = 1;
        }
        t.workgroupStride = workgroupStride;
        return t;
    }
};

bool ComputeRenderer::interleaves(const PixelWindow& area) {
    return (area.width() > kMaxTileSide || area.height() > kMaxTileSide) && area.width() <= kMaxInterleavedSide &&
           area.height() <= kMaxInterleavedSide;
}

std::vector<RenderRegion> ComputeRenderer::tiles(const PixelWindow& area, bool interleaved) {
    const TilePlan plan(area, interleaved);
    const double areaPixels = double(area.width()) * area.height();
    std::vector<RenderRegion> out;
    for (int ty = 0; ty < plan.tilesY; ++ty)
        for (int tx = 0; tx < plan.tilesX; ++tx) {
            const gpu::TileParams t = plan.tile(tx, ty);
            if (plan.interleaved)
                out.push_back({area, double(t.width) * t.height / areaPixels});
            else
                out.push_back({{int(t.originX), int(t.originY), int(t.originX + t.width), int(t.originY + t.height)}, 1.0});
        }
    return out;
}

// A render in progress: the dispatches' times, the tiles finished and their
// rays (the tile in progress adds its invocations' counts), the truncation.
struct ComputeRenderer::Progress {
    double hostMs = 0.0, gpuMs = 0.0;
    std::uint64_t raysBefore = 0;
    int tilesDone = 0;
    TruncationReport truncation;
    // With an expected cost (RenderRequest::expectedCost), of the tile in
    // progress: each share's expected cost before each of its runs of pixels,
    // in the order a workgroup takes them (trace.comp, takePixel), and the
    // tile's in all.
    std::vector<std::vector<double>> costBefore;
    std::vector<std::uint64_t> sharePixels;  // each share's pixels
    double tileCost = 0.0;
    // When the tile started, and when each workgroup was first seen running
    // and seen finished (seconds into the tile; negative: not yet); the most
    // workgroups seen running at once in the render.
    Clock::time_point tileStart;
    double lastReport = 0.0;
    std::vector<double> startedAt, finishedAt;
    std::size_t running = 1;
    // While a dispatch runs the host wakes a few times a second for this:
    // progress read from the invocations' states, and Ctrl-C.
    std::function<void()> whileRunning;
};

ComputeRenderer::TilePlan ComputeRenderer::planTiles(const RenderRequest& request,
                                                     const Specialisation& values) const {
    TilePlan plan(request.area(), request.interleavedTiles);
    // Persistent invocations (trace.comp): on a CPU device a few workgroups
    // per core keep every core busy to the end of the dispatch; on a GPU
    // enough to fill it, as many as the memory for their ray stacks allows.
    const bool wide = layout_.precision == gpu::Precision::Fp64;  // a low part per pending ray too
    const VkDeviceSize rayEntries = VkDeviceSize(values[SNELL_SPEC_RAY_STACK]) + values[SNELL_SPEC_FRONTIER];
    const VkDeviceSize bytesPerSlot =
        sizeof(gpu::SlotState) +
        rayEntries * ((wide ? 2 : 1) * sizeof(gpu::PendingRay) + values[SNELL_SPEC_MAX_MEDIA] * 4);
    const VkDeviceSize limit = context_.properties().limits.maxStorageBufferRange;
    const bool cpu = plansForCpu();
    const VkDeviceSize budget =
        cpu ? kStackBudget : std::clamp(context_.deviceLocalBytes() / 16, kStackBudget, kGpuStackBudget);
    VkDeviceSize slots = std::min(budget, limit) / bytesPerSlot;
    if (cpu)
        slots = std::min<VkDeviceSize>(slots, SNELL_WORKGROUP_SIZE * kCpuWorkgroupsPerCore *
                                                  std::max(1u, std::thread::hardware_concurrency()));
    else
        slots = std::min(slots, kGpuInvocations);
    plan.invocations =
        std::clamp<VkDeviceSize>(std::min(slots, plan.tilePixels()) / SNELL_WORKGROUP_SIZE, 1, 65535) *
        SNELL_WORKGROUP_SIZE;
    // lavapipe gives each thread a contiguous range of workgroups: the shares
    // of neighbouring workgroups are spread over the tile (trace.comp, share).
    if (cpu)
        plan.workgroupStride = spreadingStride(std::uint32_t(plan.workgroups()));
    plan.helps = values[SNELL_SPEC_HELPS] != 0;
    return plan;
}

bool ComputeRenderer::kernelFolded() const { return cached_ && cached_->folded; }

bool ComputeRenderer::kernelAddressedStacks() const {
    return cached_ && cached_->values[SNELL_SPEC_STACKS_BY_ADDRESS] != 0;
}

const char* ComputeRenderer::kernelObject() const {
    if (!cached_) return "none";
    if (!cached_->shader.shader) return "pipeline";
    return cached_->shader.fromBinary ? "shader binary" : "shader object";
}

ComputeRenderer::Pipeline& ComputeRenderer::ensurePipeline(const Specialisation& values, bool& created) {
    // The pipeline of the last render serves again when the specialisation
    // is the same, and its buffers when they are large enough (the preview).
    created = !cached_ || cached_->values != values;
    if (!created) return *cached_;
    if (cached_) destroyPipeline(*cached_);
    cached_ = std::make_unique<Pipeline>();
    createPipeline(values, *cached_);
    return *cached_;
}

void ComputeRenderer::ensureBuffers(Pipeline& p, const RenderRequest& request, const TilePlan& plan) {
    const bool wide = layout_.precision == gpu::Precision::Fp64;
    gpu::FrameParams frameLow{};
    gpu::FrameParams frame = gpu::makeFrameParams(scene_, layout_, request, &frameLow);
    gpu::splitAddress(context_.deviceAddress(sceneBuffers_[SNELL_BINDING_BVH]), frame.bvhAddressLow, frame.bvhAddressHigh);
    if (plan.invocations > p.slots) {
        for (vk::Buffer* b : {&p.counters, &p.slotStates, &p.rayStack, &p.mediaStack, &p.rayStackLow})
            context_.destroy(*b);
        const VkDeviceSize slots = plan.invocations;
        p.slots = slots;
        // Mapped: the host reads the invocations' progress while they run.
        // The counters device-local where they can be: every pixel taken is
        // an atomic on one, which on a discrete GPU would cross the bus.
        using Memory = vk::Context::Memory;
        p.counters = context_.createBuffer(counterCount(slots / SNELL_WORKGROUP_SIZE) * sizeof(std::uint32_t),
                                           kStorage, Memory::DeviceMapped);
        p.slotStates = context_.createBuffer(slots * sizeof(gpu::SlotState), kStorage, Memory::HostCached);
        p.rayStack = context_.createBuffer(slots * p.rayEntries * sizeof(gpu::PendingRay), kStack, Memory::Device);
        p.mediaStack = context_.createBuffer(slots * p.rayEntries * p.maxMedia * 4, kStack, Memory::Device);
        if (wide)
            p.rayStackLow = context_.createBuffer(slots * p.rayEntries * sizeof(gpu::PendingRay), kStorage, Memory::Device);
    }
    gpu::splitAddress(context_.deviceAddress(p.rayStack), frame.rayStackAddressLow, frame.rayStackAddressHigh);
    gpu::splitAddress(context_.deviceAddress(p.mediaStack), frame.mediaStackAddressLow, frame.mediaStackAddressHigh);
    if (plan.tilePixels() > p.tilePixels) {
        context_.destroy(p.output);
        p.tilePixels = plan.tilePixels();
        // The tile's pixels, which the host reads where the shader wrote them
        // (on lavapipe, an imageStore in a loop costs 13x a buffer store).
        p.output = context_.createBuffer(p.tilePixels * sizeof(gpu::OutputPixel), kStorage, vk::Context::Memory::HostCached);
    }

    // The frame's block after the stacks: it holds their addresses.
    context_.destroy(p.frame);
    context_.destroy(p.frameLow);
    p.frame = context_.createBufferWithData(&frame, sizeof frame, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    if (wide) p.frameLow = context_.createBufferWithData(&frameLow, sizeof frameLow, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);

    std::array<VkDescriptorBufferInfo, SNELL_BINDING_LIMIT> bufferInfo{};
    std::array<const vk::Buffer*, SNELL_BINDING_LIMIT> buffers{};

    buffers[SNELL_BINDING_OUTPUT] = &p.output;
    buffers[SNELL_BINDING_FRAME] = &p.frame;
    buffers[SNELL_BINDING_COUNTERS] = &p.counters;
    buffers[SNELL_BINDING_SLOT_STATES] = &p.slotStates;
    buffers[SNELL_BINDING_RAY_STACK] = &p.rayStack;
    buffers[SNELL_BINDING_MEDIA_STACK] = &p.mediaStack;
    buffers[SNELL_BINDING_FRAME_LOW] = &p.frameLow;
    buffers[SNELL_BINDING_RAY_STACK_LOW] = &p.rayStackLow;
    VkWriteDescriptorSetAccelerationStructureKHR accelerationInfo{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    std::vector<VkWriteDescriptorSet> writes(p.bindings.size());
    for (std::size_t k = 0; k < writes.size(); ++k) {
        const std::uint32_t i = p.bindings[k];
        writes[k] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[k].dstSet = p.set;
        writes[k].dstBinding = i;
        writes[k].descriptorCount = 1;
        writes[k].descriptorType = descriptorType(i);
        if (writes[k].descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER) {
            writes[k].pTexelBufferView = &sceneViews_[i];
        } else if (writes[k].descriptorType == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) {
            accelerationInfo.accelerationStructureCount = 1;
            accelerationInfo.pAccelerationStructures = &sphereBoxes_->top();
            writes[k].pNext = &accelerationInfo;
        } else {
            if (!buffers[i]) buffers[i] = &sceneBuffers_[i];
            bufferInfo[i] = {buffers[i]->buffer, 0, VK_WHOLE_SIZE};
            writes[k].pBufferInfo = &bufferInfo[i];
        }
    }
    vkUpdateDescriptorSets(context_.device(), static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

// Record one command buffer (`resumes`: after a barrier on the last
// dispatch's invocation states and stacks; then `record`, timed when asked),
// submit it and wait, calling progress.whileRunning while it runs.
void ComputeRenderer::submit(Pipeline& p, Progress& progress, bool timed, bool resumes,
                             const std::function<void(VkCommandBuffer)>& record) {
    VkDevice device = context_.device();
    VkCommandBuffer cmd = p.commands;
    check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    if (resumes)
        memoryBarrier(cmd, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    if (timed && p.queries) {
        vkCmdResetQueryPool(cmd, p.queries, 0, 2);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, p.queries, 0);
    }
    record(cmd);
    if (timed && p.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, p.queries, 1);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    const auto start = Clock::now();
    VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    info.commandBufferCount = 1;
    info.pCommandBuffers = &cmd;
    check(context_.submit(info, p.fence), "vkQueueSubmit");
    for (;;) {
        constexpr std::uint64_t kPollNs = 100'000'000;
        const VkResult waited =
            vkWaitForFences(device, 1, &p.fence, VK_TRUE, progress.whileRunning ? kPollNs : UINT64_MAX);
        if (waited != VK_TIMEOUT) {
            check(waited, "vkWaitForFences");
            break;
        }
        progress.whileRunning();
    }
    check(vkResetFences(device, 1, &p.fence), "vkResetFences");
    if (!timed) return;
    progress.hostMs += msSince(start);
    if (p.queries) {
        std::uint64_t stamps[2] = {0, 0};
        check(vkGetQueryPoolResults(device, p.queries, 0, 2, sizeof stamps, stamps, sizeof(std::uint64_t),
                                    VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
              "vkGetQueryPoolResults");
        progress.gpuMs += double(stamps[1] - stamps[0]) * context_.properties().limits.timestampPeriod * 1e-6;
    }
}

// The kernel (shader object or pipeline) and its descriptor set.
void ComputeRenderer::bindKernel(VkCommandBuffer cmd, const Pipeline& p) const {
    if (p.shader.shader) {
        const VkShaderStageFlagBits stage = VK_SHADER_STAGE_COMPUTE_BIT;
        context_.shaderObjects().bind(cmd, 1, &stage, &p.shader.shader);
    } else {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    }
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
}

// An empty dispatch: llvmpipe compiles a shader at its first dispatch, and
// that belongs to pipeline creation, not to the render.
void ComputeRenderer::firstDispatch(Pipeline& p) {
    const gpu::TileParams empty{};
    std::memset(p.counters.mapped, 0, SNELL_COUNTER_COUNT * sizeof(std::uint32_t));
    Progress untimed;
    submit(p, untimed, false, false, [&](VkCommandBuffer cmd) {
        bindKernel(cmd, p);
        vkCmdPushConstants(cmd, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof empty, &empty);
        vkCmdDispatch(cmd, 1, 1, 1);
    });
}

// The tile's expected cost in the order its pixels are taken: the tile is
// dealt in shares of runs of a workgroup's size, run r to share r mod W, and
// each workgroup takes its share's runs in order (trace.comp, takePixel), so
// what a workgroup has finished is, but for the pixels in progress, the
// start of its share.
void ComputeRenderer::expectTileCost(const RenderRequest& request, const TilePlan& plan,
                                     const gpu::TileParams& tile, Progress& progress) const {
    progress.costBefore.clear();
    progress.tileCost = 0.0;
    progress.tileStart = Clock::now();
    progress.lastReport = 0.0;
    if (!request.expectedCost || request.expectedCost->empty()) return;
    const CostMap& map = *request.expectedCost;
    const std::uint64_t run = SNELL_WORKGROUP_SIZE, workgroups = plan.workgroups();
    const std::uint64_t pixels = std::uint64_t(tile.width) * tile.height, runs = (pixels + run - 1) / run;
    progress.costBefore.assign(workgroups, std::vector<double>(1, 0.0));
    progress.sharePixels.assign(workgroups, 0);
    for (std::uint64_t r = 0; r < runs; ++r) {
        double cost = 0.0;
        for (std::uint64_t k = r * run; k < std::min(pixels, (r + 1) * run); ++k)
            cost += map.at(imageColumn(tile, std::uint32_t(k % tile.width)),
                           imageRow(tile, std::uint32_t(k / tile.width)));
        std::vector<double>& before = progress.costBefore[r % workgroups];
        before.push_back(before.back() + cost);
        progress.sharePixels[r % workgroups] += std::min(run, pixels - r * run);
        progress.tileCost += cost;
    }
    progress.startedAt.assign(workgroups, -1.0);
    progress.finishedAt.assign(workgroups, -1.0);
}

// The request's progress callback: finished tiles plus the share of the
// current tile done, and the rays so far. The share is of the tile's pixels
// finished, or with an expected cost, of its time: where workgroups help
// with each other's shares, the cost done; else the time so far against
// that and the time its workgroups have left (WorkgroupSchedule), once they
// have shown their pace.
void ComputeRenderer::reportProgress(const Pipeline& p, const RenderRequest& request, const TilePlan& plan,
                                     const gpu::TileParams& tile, Progress& progress, bool tileDone) const {
    const auto* states = static_cast<const gpu::SlotState*>(p.slotStates.mapped);
    const std::uint64_t run = SNELL_WORKGROUP_SIZE, workgroups = plan.workgroups();
    const std::uint64_t pixels = std::uint64_t(tile.width) * tile.height;
    const double now = std::chrono::duration<double>(Clock::now() - progress.tileStart).count();
    const double seenAt = 0.5 * (progress.lastReport + now);  // between the last report and this one
    std::uint64_t finished = 0, rays = progress.raysBefore;
    double costDone = 0.0;
    std::size_t runningNow = 0;
    // The expected cost of a share's first `count` pixels (the order it is taken in).
    auto costOfFirst = [&](std::uint64_t share, std::uint64_t count) {
        const std::vector<double>& before = progress.costBefore[share];
        const std::size_t runsDone = std::min<std::size_t>(count / run, before.size() - 1);
        double done = before[runsDone];
        if (runsDone + 1 < before.size()) {
            const std::uint64_t first = (runsDone * workgroups + share) * run;  // that run's first pixel
            done += double(count % run) / double(std::min(run, pixels - first)) *
                    (before[runsDone + 1] - before[runsDone]);
        }
        return std::min(done, before.back());
    };
    std::vector<WorkgroupWork> work(progress.tileCost > 0.0 && !plan.helps ? workgroups : 0);
    for (std::uint64_t w = 0; w < workgroups; ++w) {
        std::uint64_t ofWorkgroup = 0;
        for (std::uint64_t k = w * run; k < (w + 1) * run; ++k) {
            ofWorkgroup += states[k].finished;
            rays += states[k].rays;
        }
        finished += ofWorkgroup;
        if (work.empty()) continue;
        // Its finished pixels are (but for those in progress) its share's first runs'.
        const std::uint64_t share = plan.shareOf(w);
        WorkgroupWork& wg = work[w];
        wg.done = costOfFirst(share, ofWorkgroup);
        wg.total = progress.costBefore[share].back();
        costDone += wg.done;
        if (wg.done > 0.0 && progress.startedAt[w] < 0.0) progress.startedAt[w] = seenAt;
        if (wg.done >= wg.total && progress.finishedAt[w] < 0.0) progress.finishedAt[w] = seenAt;
        if (progress.startedAt[w] >= 0.0) {
            const bool over = progress.finishedAt[w] >= 0.0;
            wg.secondsRunning = std::max((over ? progress.finishedAt[w] : now) - progress.startedAt[w], 1e-6);
            if (!over) ++runningNow;
        }
    }
    progress.lastReport = now;
    progress.running = std::max(progress.running, runningNow);
    double share = double(finished) / double(pixels);
    if (plan.helps && progress.tileCost > 0.0 && finished < pixels) {
        // Every workgroup works on while any share has pixels left, so the
        // tile's time goes with its cost: the cost of the pixels taken (each
        // share's counter), less those still in flight at the average cost.
        const auto* counters = static_cast<const std::uint32_t*>(p.counters.mapped);
        double costTaken = 0.0;
        std::uint64_t taken = 0;
        for (std::uint64_t s = 0; s < workgroups; ++s) {
            const std::uint64_t t =
                std::min<std::uint64_t>(counters[SNELL_COUNTER_COUNT + s * SNELL_COUNTER_STRIDE], progress.sharePixels[s]);
            costTaken += costOfFirst(s, t);
            taken += t;
        }
        if (taken > 0) share = std::min(0.999, costTaken * std::min(1.0, double(finished) / double(taken)) / progress.tileCost);
    } else if (!work.empty() && finished < pixels) {
        const double left = scheduleSecondsLeft(work, progress.running);
        share = left >= 0.0 && now > 0.0 ? now / (now + left) : costDone / progress.tileCost;
        share = std::min(share, 0.999);
    }
    if (request.progress) request.progress((progress.tilesDone + share) / plan.count(), rays);
    if (tileDone) progress.raysBefore = rays;
}

// One tile: a dispatch traces it; where the driver limits loops, the
// invocations suspend and the next dispatch resumes them, until none is left
// unfinished. Adds the counters to `result`.
void ComputeRenderer::dispatchTile(Pipeline& p, const RenderRequest& request, const TilePlan& plan,
                                   gpu::TileParams tile, bool countRays, Progress& progress, GpuRenderResult& result) {
    auto* counters = static_cast<std::uint32_t*>(p.counters.mapped);
    const std::uint32_t groups = std::uint32_t(plan.invocations / SNELL_WORKGROUP_SIZE);
    if (request.progress) expectTileCost(request, plan, tile, progress);
    progress.whileRunning = [&] {
        if (request.cancel && request.cancel->load())
            std::atomic_ref<std::uint32_t>(counters[SNELL_COUNTER_CANCEL]).store(1u);
        reportProgress(p, request, plan, tile, progress, false);
    };
    for (int pass = 0;; ++pass) {
        if (request.cancel && request.cancel->load()) throw vk::VulkanError("render cancelled");
        // A resumed dispatch goes on taking the workgroups' pixels where the last one stopped.
        std::memset(counters, 0, (pass > 0 ? SNELL_COUNTER_COUNT : counterCount(groups)) * sizeof(std::uint32_t));
        if (pass == 0) {
            setBits(counters, shareBitsAt(groups), groups);
            setBits(counters, wordBitsAt(groups), shareWords(groups));
        }
        tile.resume = pass > 0 ? 1u : 0u;
        if (pass == 0) std::memset(p.slotStates.mapped, 0, plan.invocations * sizeof(gpu::SlotState));
        submit(p, progress, true, pass > 0, [&](VkCommandBuffer cmd) {
            bindKernel(cmd, p);
            vkCmdPushConstants(cmd, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof tile, &tile);
            vkCmdDispatch(cmd, groups, 1, 1);
            memoryBarrier(cmd, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT);
        });
        ++result.dispatches;
        if (counters[SNELL_COUNTER_LOOP_LIMIT] != 0)
            throw vk::VulkanError("a single ray needed more loop iterations than lavapipe allows in one "
                                  "dispatch (65535 per SIMD row); the image would be wrong. Try fewer "
                                  "lights or a smaller --depth");
        progress.truncation.deepest = std::max(progress.truncation.deepest, int(counters[SNELL_COUNTER_DEEPEST]));
        result.stackOverflows += counters[SNELL_COUNTER_OVERFLOW];
        if (countLanes_) {
            result.lanes.traceSlots += counters[SNELL_COUNTER_TRACE_SLOTS];
            result.lanes.traceBusy += counters[SNELL_COUNTER_TRACE_BUSY];
            result.lanes.walkSlots += counters[SNELL_COUNTER_WALK_SLOTS];
            result.lanes.walkBusy += counters[SNELL_COUNTER_WALK_BUSY];
        }
        if (countRays) {
            result.rays.primary += counters[SNELL_COUNTER_PRIMARY];
            result.rays.shadow += counters[SNELL_COUNTER_SHADOW];
            result.rays.reflected += counters[SNELL_COUNTER_REFLECTED];
            result.rays.refracted += counters[SNELL_COUNTER_REFRACTED];
        }
        const std::uint32_t unfinished = counters[SNELL_COUNTER_UNFINISHED];
        if (request.cancel && request.cancel->load()) throw vk::VulkanError("render cancelled");
        reportProgress(p, request, plan, tile, progress, unfinished == 0);
        if (unfinished == 0) break;
    }
    progress.whileRunning = nullptr;
}

// The finished tile, from where the shader wrote it, into `rows` (the image,
// or the band of rows being streamed, whose first row is `firstRow` of the
// window), with each pixel's truncation bound.
void ComputeRenderer::readBackTile(const Pipeline& p, const RenderRequest& request, const TilePlan& plan,
                                   const gpu::TileParams& tile, Image& rows, int firstRow, Progress& progress,
                                   GpuRenderResult& result) const {
    const auto readStart = Clock::now();
    const PixelWindow& area = plan.area;
    TruncationReport& truncation = progress.truncation;
    const auto* pixels = static_cast<const gpu::OutputPixel*>(p.output.mapped);
    for (std::uint32_t y = 0; y < tile.height; ++y) {
        const int imageY = imageRow(tile, y), windowRow = imageY - area.y0;
        float* row = rows.pixel(0, windowRow - firstRow);
        const gpu::OutputPixel* src = pixels + std::size_t(y) * tile.width;
        for (std::uint32_t x = 0; x < tile.width; ++x) {
            const gpu::OutputPixel& out = src[x];
            const int imageX = imageColumn(tile, x), column = imageX - area.x0;
            row[column * 3 + 0] = out.colour.r;
            row[column * 3 + 1] = out.colour.g;
            row[column * 3 + 2] = out.colour.b;
            // The pixel's truncation bound, negative where not finite.
            const float bound = std::abs(out.colour.a);
            PixelTruncation pixel;
            pixel.x = imageX;
            pixel.y = imageY;
            pixel.bound = bound;
            pixel.unbounded = out.colour.a < 0.0f;
            pixel.overBudget = out.truncation.y != 0.0f;
            pixel.overTolerance = out.truncation.z != 0.0f;
            pixel.estimated = out.truncation.x >= 0.0f;
            pixel.estimatedError = std::max(0.0f, out.truncation.x);
            pixel.droppedGrowing = out.truncation.z == 2.0f;
            truncation.add(pixel);
            if (request.boundImage)
                (*request.boundImage)[std::size_t(windowRow) * area.width() + column] = bound;
            if (request.rayImage)
                (*request.rayImage)[std::size_t(windowRow) * area.width() + column] = out.truncation.w;
        }
    }
    result.readbackMs += msSince(readStart);
    ++result.tiles;
    ++progress.tilesDone;
}

// Plan the tiles, make sure of the pipeline and its buffers, then each tile:
// dispatch it and read it back (streaming a band of tiles at a time).
GpuRenderResult ComputeRenderer::render(const RenderRequest& request, bool countRays) {
    GpuRenderResult result;
    try {
        const auto pipelineStart = Clock::now();
        const Specialisation values = specialise(request, countRays);
        const TilePlan plan = planTiles(request, values);
        result.invocations = static_cast<int>(plan.invocations);
        result.interleaved = plan.interleaved;
        bool created = false;
        Pipeline& p = ensurePipeline(values, created);
        ensureBuffers(p, request, plan);
        if (created) firstDispatch(p);
        result.pipelineMs = msSince(pipelineStart);

        const PixelWindow& area = plan.area;
        if (request.boundImage) request.boundImage->assign(std::size_t(area.width()) * area.height(), 0.0f);
        if (request.rayImage) request.rayImage->assign(std::size_t(area.width()) * area.height(), 0.0f);
        if (!request.rowSink) result.image = Image(area.width(), area.height());
        // Streaming rows: a band at a time (TilePlan::bandRows).
        const int bandRows = plan.bandRows();
        Image band = request.rowSink ? Image(area.width(), bandRows) : Image();
        Progress progress;
        for (int ty = 0; ty < plan.tilesY; ++ty) {
            const int bandRow = plan.interleaved ? 0 : ty * plan.tileHeight;
            for (int tx = 0; tx < plan.tilesX; ++tx) {
                const gpu::TileParams tile = plan.tile(tx, ty);
                dispatchTile(p, request, plan, tile, countRays, progress, result);
                if (request.rowSink) readBackTile(p, request, plan, tile, band, bandRow, progress, result);
                else readBackTile(p, request, plan, tile, result.image, 0, progress, result);
            }
            const bool bandDone = !plan.interleaved || ty + 1 == plan.tilesY;
            if (request.rowSink && bandDone) request.rowSink(band.rgb.data(), std::min(bandRows, area.height() - bandRow));
        }
        if (request.truncation) *request.truncation = progress.truncation;
        result.tracedRays = progress.raysBefore;
        result.rayStack = values[SNELL_SPEC_RAY_STACK];
        result.gpuTimed = p.queries != VK_NULL_HANDLE;
        result.renderMs = result.gpuTimed ? progress.gpuMs : progress.hostMs;
    } catch (...) {
        // Whatever failed, the kept pipeline's state is unknown: start afresh.
        if (cached_) destroyPipeline(*cached_);
        cached_.reset();
        throw;
    }
    return result;
}

}  // namespace snell
