// The compute renderer: uploads a scene's GPU layout (GpuScene.h), builds the
// pipeline of shaders/trace.comp specialised to the scene, and renders images
// in tiles so no single submission runs for long.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>

#include "gpu/GpuScene.h"
#include "image/Image.h"
#include "render/RenderRequest.h"
#include "vulkan/BoxAccelerationStructure.h"
#include "vulkan/VulkanContext.h"

namespace snell {

struct GpuRenderResult {
    Image image;
    RayCounts rays;           // filled when counting was asked for
    std::uint64_t tracedRays = 0;  // all rays traced, as the invocations report them for progress (always)
    double renderMs = 0.0;    // the dispatches alone
    bool gpuTimed = false;    // renderMs from GPU timestamps (else host timing)
    double pipelineMs = 0.0;  // shader pipeline creation
    double readbackMs = 0.0;  // copying tiles back into the image
    int tiles = 0;
    bool interleaved = false;  // the tiles interleaved (RenderRequest::interleavedTiles), else blocks
    int dispatches = 0;       // more than one a tile where the driver limits loops (shared_layout.h)
    int invocations = 0;      // persistent invocations a dispatch (trace.comp)
    std::uint32_t rayStack = 0;        // entries of each invocation's ray stack
    std::uint64_t stackOverflows = 0;  // rays dropped on a full stack (their weight is in the bound)
    // With countLanes(true): SIMD lane slots (a subgroup's size, each pass it
    // makes) and the lanes busy in them, of the trace loop and of the BVH walk.
    struct Lanes {
        std::uint64_t traceSlots = 0, traceBusy = 0, walkSlots = 0, walkBusy = 0;
    } lanes;
};

class ComputeRenderer {
public:
    // Uploads the scene; `camera.eye` becomes the GPU's coordinate origin.
    // Fp64 needs the device's shaderFloat64 feature (else vk::VulkanError).
    // Traversal::RayQuery needs ray queries enabled in the context and fp32
    // (else vk::VulkanError), and searches every scene of two spheres or
    // more through them; Auto uses them for BVH scenes on a GPU where enabled.
    ComputeRenderer(vk::Context& context, const Scene& scene, const Camera& camera,
                    gpu::Precision precision = gpu::Precision::Fp32, gpu::BvhMode bvh = gpu::BvhMode::Auto,
                    gpu::Traversal traversal = gpu::Traversal::Auto);
    ~ComputeRenderer();
    ComputeRenderer(const ComputeRenderer&) = delete;
    ComputeRenderer& operator=(const ComputeRenderer&) = delete;

    double uploadMs() const { return uploadMs_; }
    const gpu::GpuScene& layout() const { return layout_; }
    // How the spheres are searched: "ray-query" (the device's traversal),
    // "bvh" (snell's walk) or "loop" (every sphere, a small scene).
    const char* traversal() const;

    // Render request.camera (any camera; coordinates stay relative to the
    // origin chosen for the construction camera). The pipeline and tile
    // buffers are kept for the next render, which reuses them when it can.
    GpuRenderResult render(const RenderRequest& request, bool countRays);

    // The largest tile side: an image is rendered (and streamed) tile by tile.
    static constexpr int kMaxTileSide = 1024;
    // Up to this side, where asked (RenderRequest::interleavedTiles), a
    // window of more than one tile is cut into interleaved tiles (tile (i, j)
    // of n × m: every n-th run of columns from run i, every m-th run of rows
    // from run j; shared_layout.h, TileParams), each a fair sample of the
    // whole image, so the first tile's time forecasts the others' and the
    // progress bar's time left holds where cost is uneven over the image;
    // the image is streamed once all are done. Otherwise blocks, streamed a
    // band of rows at a time. Interleaving cost 6–12 % where workgroups keep
    // to their own shares (no refraction, no BVH), nothing measurable where
    // they help each other (docs/performance.md).
    static constexpr int kMaxInterleavedSide = 2 * kMaxTileSide;
    static bool interleaves(const PixelWindow& area);
    // The tiles render() traces `area` in, in that order; its progress
    // fraction counts finished tiles plus the share of the current tile's
    // pixels finished, over the tile count.
    static std::vector<RenderRegion> tiles(const PixelWindow& area, bool interleaved);

    // Testing: suspend and resume the invocations every `budget` loop
    // iterations (SNELL_LOOP_BUDGET), as on a driver that limits loops,
    // whatever this driver does. The image must not change.
    void forceLoopBudget(std::uint32_t budget) { loopBudget_ = budget; }
    // Measuring: count the lanes busy in each loop pass (GpuRenderResult::lanes; slower).
    void countLanes(bool count) { countLanes_ = count; }
    // Testing: plan as for a GPU (its invocations, frontiers and shares) on a
    // CPU device, so lavapipe runs the paths a GPU takes. A fixed tree's
    // image must not change; under a tolerance the shorter frontiers may
    // trace some rays a step early, within the bounds.
    void planAsGpu(bool asGpu) { planAsGpu_ = asGpu; }
    // With false, the driver specialises the kernel as compiled; by default
    // its constants are folded in first, where the context keeps a cache
    // (vulkan/SpecialisedModule.h). The image is the same either way.
    void foldSpecialisation(bool fold) { foldSpecialisation_ = fold; }
    bool kernelFolded() const;  // the last render's kernel had its specialisation folded in
    // Testing: whether the BVH walk reads the nodes through their device
    // address or as texels (by default as the driver reads faster). The
    // image is the same.
    void readBvhWords(bool words) { bvhWords_ = words; }
    bool readsBvhWords() const { return bvhWords_; }
    // Testing: whether the ray and media stacks are read and written through
    // their device addresses or as storage buffers (by default as the driver
    // does faster). The image is the same.
    void addressStacks(bool byAddress) { stacksByAddress_ = byAddress; }
    bool kernelAddressedStacks() const;  // the last render's kernel did
    // Testing: whether the walk's stack may live in registers where it fits
    // (SNELL_REGISTER_STACK_LIMIT; by default on CPU devices), else an array at
    // a per-lane index. The image is the same either way.
    void keepStackInRegisters(bool registers) { stackInRegisters_ = registers; }
    bool stackInRegisters() const;  // the walk's stack is in registers (this scene, this setting)
    // Testing: whether the shadow rays of a subgroup's hits may be shared out
    // among all its lanes (trace.comp, shadeLightsShared; by default they
    // are, where the device and scene allow it), or each lane walks its own
    // in the lights' loop. The image is the same either way.
    void shareShadowRays(bool share) { shareShadowRays_ = share; }
    bool sharesShadowRays() const;  // this scene's shadow rays are shared out (this device, this setting)
    // With false, the kernel is a pipeline even where the device has shader
    // objects (vulkan/ShaderObject.h). The image is the same either way.
    void useShaderObjects(bool use) { useShaderObjects_ = use; }
    // The last render's kernel: "pipeline", "shader object" (made from its
    // SPIR-V, its binary kept), or "shader binary" (from a kept binary).
    const char* kernelObject() const;

private:
    struct Pipeline;
    struct TilePlan;
    struct Progress;
    using Specialisation = std::array<std::uint32_t, SNELL_SPEC_COUNT>;
    Specialisation specialise(const RenderRequest& request, bool countRays) const;
    void createPipeline(const Specialisation& values, Pipeline& pipeline);
    void createKernel(Pipeline& pipeline, std::span<const std::uint32_t> code);
    void bindKernel(VkCommandBuffer cmd, const Pipeline& pipeline) const;
    void destroyPipeline(Pipeline& pipeline);
    // The phases of render(), in order.
    TilePlan planTiles(const RenderRequest& request, const Specialisation& values) const;
    Pipeline& ensurePipeline(const Specialisation& values, bool& created);
    void ensureBuffers(Pipeline& p, const RenderRequest& request, const TilePlan& plan);
    void firstDispatch(Pipeline& p);
    void dispatchTile(Pipeline& p, const RenderRequest& request, const TilePlan& plan, gpu::TileParams tile,
                      bool countRays, Progress& progress, GpuRenderResult& result);
    void readBackTile(const Pipeline& p, const RenderRequest& request, const TilePlan& plan,
                      const gpu::TileParams& tile, Image& rows, int firstRow, Progress& progress,
                      GpuRenderResult& result) const;
    void expectTileCost(const RenderRequest& request, const TilePlan& plan, const gpu::TileParams& tile,
                        Progress& progress) const;
    void reportProgress(const Pipeline& p, const RenderRequest& request, const TilePlan& plan,
                        const gpu::TileParams& tile, Progress& progress, bool tileDone) const;
    void submit(Pipeline& p, Progress& progress, bool timed, bool resumes,
                const std::function<void(VkCommandBuffer)>& record);
    void destroyBuffers();
    bool spheresInBlock() const;  // every sphere in the uniform block (shared_layout.h)

    vk::Context& context_;
    const Scene& scene_;
    gpu::GpuScene layout_;
    // The scene's buffers, by binding (shared_layout.h); the others stay empty.
    std::array<vk::Buffer, SNELL_BINDING_COUNT> sceneBuffers_{};
    std::array<VkBufferView, SNELL_BINDING_COUNT> sceneViews_{};
    bool plansForCpu() const { return context_.isCpuDevice() && !planAsGpu_; }
    bool planAsGpu_ = false;
    bool foldSpecialisation_ = true;
    bool useShaderObjects_ = true;
    bool bvhWords_ = false;
    bool stacksByAddress_ = false;
    bool stackInRegisters_ = false;
    bool shareShadowRays_ = true;
    bool deviceSharesShadowRays_ = false;  // a CPU device with subgroups of up to 16 lanes
    std::uint32_t loopBudget_ = 0;  // where the driver ends long loops (gpu/DriverProbe.h), else 0
    bool countLanes_ = false;
    double uploadMs_ = 0.0;
    std::unique_ptr<vk::BoxAccelerationStructure> sphereBoxes_;  // the ray-query traversal's, else null
    std::unique_ptr<Pipeline> cached_;  // the last render's, reused by the next when it fits
};

}  // namespace snell
