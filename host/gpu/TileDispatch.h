// Dispatch and resume: a tile's dispatch, and where the driver limits loops
// the dispatches that resume its suspended invocations, until none is left
// unfinished; each submission waited on while progress is reported.
#pragma once

#include <functional>

#include "gpu/GpuRenderResult.h"
#include "gpu/KernelPipeline.h"
#include "gpu/ProgressForecast.h"
#include "gpu/TilePlan.h"

namespace snell::gpu {

// Records one command buffer (`resumes`: after a barrier on the last
// dispatch's invocation states and stacks; then `record`, timed when asked),
// submits it and waits, calling progress.whileRunning while it runs.
void submit(vk::Context& context, Kernel& kernel, RenderProgress& progress, bool timed, bool resumes,
            const std::function<void(VkCommandBuffer)>& record);

// An empty dispatch: llvmpipe compiles a shader at its first dispatch, and
// that belongs to pipeline creation, not to the render.
void firstDispatch(vk::Context& context, Kernel& kernel);

// Traces one tile; adds its counters (rays with countRays, lanes with
// countLanes) to `result`. Throws vk::VulkanError when the request is
// cancelled or a ray needs more loop iterations than the driver allows.
void dispatchTile(vk::Context& context, Kernel& kernel, const RenderRequest& request, const TilePlan& plan,
                  TileParams tile, bool countRays, bool countLanes, RenderProgress& progress,
                  GpuRenderResult& result);

}  // namespace snell::gpu
