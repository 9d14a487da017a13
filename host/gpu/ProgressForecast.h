// A render's progress while its dispatches run: the share of the tile done,
// read from the invocations' states, and where the request gives each
// pixel's expected cost, the share of its time (render/WorkgroupSchedule.h).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "common/Clock.h"
#include "gpu/TilePlan.h"
#include "render/Truncation.h"

namespace snell::gpu {

// A render in progress: the dispatches' times, the tiles finished and their
// rays (the tile in progress adds its invocations' counts), the truncation.
struct RenderProgress {
    double hostMs = 0.0, gpuMs = 0.0;
    std::uint64_t raysBefore = 0;
    int tilesDone = 0;
    TruncationReport truncation;
    // With an expected cost (RenderRequest::expectedCost), of the tile in
    // progress: each share's expected cost before each of its runs of pixels,
    // in the order a workgroup takes them (schedule/pixels.glsl, takePixel), and the
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

// Starts the tile: its expected cost in the order its pixels are taken.
void expectTileCost(const RenderRequest& request, const TilePlan& plan, const TileParams& tile,
                    RenderProgress& progress);

// Calls the request's progress callback: finished tiles plus the share of
// the current tile done, and the rays so far, from the invocations' states
// and the shares' counters (shared_layout.h).
void reportProgress(const SlotState* states, const std::uint32_t* counters, const RenderRequest& request,
                    const TilePlan& plan, const TileParams& tile, RenderProgress& progress, bool tileDone);

}  // namespace snell::gpu
