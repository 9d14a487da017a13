// What a render on the device returns: the image, its rays and counters, and
// where its time went.
#pragma once

#include <cstdint>

#include "image/Image.h"
#include "render/RenderRequest.h"

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
    // With RendererOptions::countLanes: SIMD lane slots (a subgroup's size,
    // each pass it makes) and the lanes busy in them, of the trace loop and
    // of the BVH walk.
    struct Lanes {
        std::uint64_t traceSlots = 0, traceBusy = 0, walkSlots = 0, walkBusy = 0;
    } lanes;
};

}  // namespace snell
