#include "gpu/ComputeRenderer.h"

#include <algorithm>

#include "common/Clock.h"
#include "gpu/KernelPipeline.h"
#include "gpu/ProgressForecast.h"
#include "gpu/SceneUpload.h"
#include "gpu/TileDispatch.h"
#include "gpu/TileReadback.h"

namespace snell {

ComputeRenderer::ComputeRenderer(vk::Context& context, const Scene& scene, const Camera& camera,
                                 const RendererOptions& options)
    : context_(context), scene_(scene), options_(options) {
    const bool rayQuery = gpu::choosesRayQueries(context, options_);
    const auto start = Clock::now();
    layout_ = gpu::buildGpuScene(scene, camera, options_.precision, options_.bvh, rayQuery);
    policy_ = gpu::devicePolicy(context, options_, layout_);
    sceneBuffers_ = std::make_unique<gpu::SceneBuffers>(context, layout_, policy_.spheresInBlock);
    uploadMs_ = msSince(start);
}

ComputeRenderer::~ComputeRenderer() { dropKernel(); }

const char* ComputeRenderer::traversal() const {
    return sceneBuffers_->sphereBoxes() ? "ray-query" : layout_.usesBvh() ? "bvh" : "loop";
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

void ComputeRenderer::dropKernel() {
    if (cached_) gpu::destroyKernel(context_, *cached_);
    cached_.reset();
}

gpu::Kernel& ComputeRenderer::ensureKernel(const gpu::Specialisation& values, bool& created) {
    // The kernel of the last render serves again when the specialisation is
    // the same, and its buffers when they are large enough (the preview).
    created = !cached_ || cached_->values != values;
    if (!created) return *cached_;
    dropKernel();
    cached_ = std::make_unique<gpu::Kernel>();
    gpu::KernelBuild build;
    build.wide = layout_.precision == gpu::Precision::Fp64;
    build.rayQuery = sceneBuffers_->sphereBoxes() != nullptr;
    build.fold = options_.foldSpecialisation;
    build.shaderObjects = options_.useShaderObjects;
    gpu::createKernel(context_, values, build, *cached_);
    return *cached_;
}

gpu::Kernel& ComputeRenderer::readyKernel(const RenderRequest& request, const gpu::Specialisation& values,
                                          const gpu::TilePlan& plan, bool& created) {
    gpu::Kernel& k = ensureKernel(values, created);
    gpu::FrameParams frameLow{};
    const gpu::FrameParams frame = gpu::makeFrameParams(scene_, layout_, request, &frameLow);
    gpu::prepareBuffers(context_, k, *sceneBuffers_, frame, frameLow, plan.invocations, plan.tilePixels());
    if (created) gpu::firstDispatch(context_, k);
    return k;
}

bool ComputeRenderer::prepare(const RenderRequest& request, bool countRays) {
    try {
        const gpu::Specialisation values = gpu::specialise(scene_, layout_, policy_, request, countRays);
        const bool wide = layout_.precision == gpu::Precision::Fp64;
        bool created = false;
        readyKernel(request, values, gpu::planTiles(context_, request, values, wide, policy_.planForCpu), created);
        return created;
    } catch (...) {
        dropKernel();
        throw;
    }
}

// Plan the tiles, make sure of the kernel and its buffers, then each tile:
// dispatch it and read it back (streaming a band of tiles at a time).
GpuRenderResult ComputeRenderer::render(const RenderRequest& request, bool countRays) {
    GpuRenderResult result;
    try {
        const auto pipelineStart = Clock::now();
        const gpu::Specialisation values = gpu::specialise(scene_, layout_, policy_, request, countRays);
        const bool wide = layout_.precision == gpu::Precision::Fp64;
        const gpu::TilePlan plan = gpu::planTiles(context_, request, values, wide, policy_.planForCpu);
        result.invocations = static_cast<int>(plan.invocations);
        result.interleaved = plan.interleaved;
        bool created = false;
        gpu::Kernel& k = readyKernel(request, values, plan, created);
        result.pipelineMs = msSince(pipelineStart);

        const PixelWindow& area = plan.area;
        request.startTruncationImages(std::size_t(area.width()) * area.height());
        if (request.rayImage) request.rayImage->assign(std::size_t(area.width()) * area.height(), 0.0f);
        if (!request.rowSink) result.image = Image(area.width(), area.height());
        // Streaming rows: a band at a time (TilePlan::bandRows).
        const int bandRows = plan.bandRows();
        Image band = request.rowSink ? Image(area.width(), bandRows) : Image();
        const auto* pixels = static_cast<const gpu::OutputPixel*>(k.output.mapped);
        const auto* flagged = k.values[SNELL_SPEC_BY_SAMPLE] != 0
                                  ? static_cast<const gpu::FlaggedSamples*>(k.flagged.mapped)
                                  : nullptr;
        const gpu::SceneFacts facts{scene_.lights.size()};
        gpu::RenderProgress progress;
        for (int ty = 0; ty < plan.tilesY; ++ty) {
            const int bandRow = plan.interleaved ? 0 : ty * plan.tileHeight;
            for (int tx = 0; tx < plan.tilesX; ++tx) {
                const gpu::TileParams tile = plan.tile(tx, ty);
                gpu::dispatchTile(context_, k, request, plan, tile, countRays, policy_.countLanes, progress, result);
                if (request.rowSink)
                    gpu::readBackTile(pixels, flagged, request, plan, tile, facts, band, bandRow, progress, result);
                else gpu::readBackTile(pixels, flagged, request, plan, tile, facts, result.image, 0, progress, result);
            }
            const bool bandDone = !plan.interleaved || ty + 1 == plan.tilesY;
            if (request.rowSink && bandDone) request.rowSink(band.rgb.data(), std::min(bandRows, area.height() - bandRow));
        }
        if (request.truncation) *request.truncation = progress.truncation;
        result.tracedRays = progress.raysBefore;
        result.rayStack = values[SNELL_SPEC_RAY_STACK];
        result.gpuTimed = k.queries != VK_NULL_HANDLE;
        result.renderMs = result.gpuTimed ? progress.gpuMs : progress.hostMs;
    } catch (...) {
        // Whatever failed, the kept kernel's state is unknown: start afresh.
        dropKernel();
        throw;
    }
    return result;
}

}  // namespace snell
