// The compute renderer: uploads a scene's GPU layout (GpuScene.h), builds the
// kernel of shaders/trace.comp specialised to the scene, and renders images
// in tiles so no single submission runs for long. Its parts: the device
// policy and specialisation (KernelPolicy.h), the upload (SceneUpload.h), the
// kernel and its buffers (KernelPipeline.h), the tile plan (TilePlan.h),
// dispatch and resume (TileDispatch.h), the progress forecast
// (ProgressForecast.h) and the readback (TileReadback.h).
#pragma once

#include <memory>
#include <vector>

#include "gpu/GpuRenderResult.h"
#include "gpu/GpuScene.h"
#include "gpu/KernelPolicy.h"
#include "gpu/RendererOptions.h"
#include "gpu/TilePlan.h"
#include "render/RenderRequest.h"
#include "vulkan/VulkanContext.h"

namespace snell {

namespace gpu {
class SceneBuffers;
struct Kernel;
}  // namespace gpu

class ComputeRenderer {
public:
    // Uploads the scene; `camera.eye` becomes the GPU's coordinate origin.
    // Throws vk::VulkanError where the device cannot trace as `options` ask:
    // fp64 without the shaderFloat64 feature, or ray queries the context has
    // not enabled or combined with fp64 (RendererOptions.h).
    ComputeRenderer(vk::Context& context, const Scene& scene, const Camera& camera,
                    const RendererOptions& options = {});
    ~ComputeRenderer();
    ComputeRenderer(const ComputeRenderer&) = delete;
    ComputeRenderer& operator=(const ComputeRenderer&) = delete;

    double uploadMs() const { return uploadMs_; }
    const gpu::GpuScene& layout() const { return layout_; }
    // How the spheres are searched: "ray-query" (the device's traversal),
    // "bvh" (snell's walk) or "loop" (every sphere, a small scene).
    const char* traversal() const;

    // Render request.camera (any camera; coordinates stay relative to the
    // origin chosen for the construction camera). The kernel and tile
    // buffers are kept for the next render, which reuses them when it can.
    GpuRenderResult render(const RenderRequest& request, bool countRays);
    // Builds the kernel that render(request, countRays) will use, so that
    // its compile (seconds on lavapipe for a new scene structure, where no
    // cache holds it) can be announced and timed apart from the render.
    // Returns true where it built one, false where the last render's serves.
    bool prepare(const RenderRequest& request, bool countRays);

    // The largest tile side: an image is rendered (and streamed) tile by tile.
    static constexpr int kMaxTileSide = gpu::kMaxTileSide;
    // Up to this side, where asked (RenderRequest::interleavedTiles), a
    // window of more than one tile is cut into interleaved tiles (tile (i, j)
    // of n × m: every n-th run of columns from run i, every m-th run of rows
    // from run j; shared_layout.h, TileParams), each a fair sample of the
    // whole image, so the first tile's time forecasts the others' and the
    // progress bar's time left holds where cost is uneven over the image;
    // the image is streamed once all are done. Otherwise blocks, streamed a
    // band of rows at a time. Interleaving cost 6–12 % where workgroups keep
    // to their own shares (no refraction, no BVH), nothing measurable where
    // they help each other (docs/log/writing-images.md, "Interleaved tiles").
    static constexpr int kMaxInterleavedSide = gpu::kMaxInterleavedSide;
    static bool interleaves(const PixelWindow& area) { return gpu::interleaves(area); }
    // The tiles render() traces `area` in, in that order; its progress
    // fraction counts finished tiles plus the share of the current tile's
    // pixels finished, over the tile count.
    static std::vector<RenderRegion> tiles(const PixelWindow& area, bool interleaved) {
        return gpu::tileRegions(area, interleaved);
    }

    // What the last render's kernel was, and the paths this scene takes here.
    bool kernelFolded() const;  // its specialisation folded in (RendererOptions::foldSpecialisation)
    bool kernelAddressedStacks() const;  // its stacks read through their addresses
    bool stackInRegisters() const { return policy_.stackInRegisters; }
    bool sharesShadowRays() const { return policy_.sharesShadowRays; }
    // "pipeline", "shader object" (made from its SPIR-V, its binary kept), or
    // "shader binary" (from a kept binary).
    const char* kernelObject() const;

private:
    gpu::Kernel& ensureKernel(const gpu::Specialisation& values, bool& created);
    // The kernel and its buffers for `request`, as planned (its first,
    // compiling dispatch done where it is new).
    gpu::Kernel& readyKernel(const RenderRequest& request, const gpu::Specialisation& values,
                             const gpu::TilePlan& plan, bool& created);
    void dropKernel();

    vk::Context& context_;
    const Scene& scene_;
    RendererOptions options_;
    gpu::GpuScene layout_;
    gpu::KernelPolicy policy_;
    double uploadMs_ = 0.0;
    std::unique_ptr<gpu::SceneBuffers> sceneBuffers_;
    std::unique_ptr<gpu::Kernel> cached_;  // the last render's, reused by the next when it fits
};

}  // namespace snell
