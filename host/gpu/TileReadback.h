// Readback: a finished tile, from where the kernel wrote it, into the image
// (or the band of rows being streamed), with each pixel's truncation bound.
#pragma once

#include "gpu/GpuRenderResult.h"
#include "gpu/ProgressForecast.h"
#include "gpu/TilePlan.h"

namespace snell::gpu {

// `rows` is the image, or the band being streamed, whose first row is
// `firstRow` of the window; also fills the request's bound and ray images.
// A pixel the kernel left undecided (physics/margins.glsl) is re-traced by
// request.retrace where that is set and its undecided light is more than a
// bound should take, else its bound is widened.
struct SceneFacts {
    std::size_t lights = 0;
};
// `flagged`: each pixel's FlaggedSamples, where the kernel kept them (else
// null): a supersampled pixel then re-traces only its flagged samples.
void readBackTile(const OutputPixel* pixels, const FlaggedSamples* flagged, const RenderRequest& request, const TilePlan& plan,
                  const TileParams& tile, const SceneFacts& facts, Image& rows, int firstRow, RenderProgress& progress,
                  GpuRenderResult& result);

}  // namespace snell::gpu
