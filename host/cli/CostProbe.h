// The progress bar's probe: a sparse render of the same image, before the
// render, whose time and rays foretell each region's (Progress.h).
#pragma once

#include <functional>
#include <utility>
#include <vector>

#include "cli/Progress.h"
#include "render/RenderRequest.h"
#include "scene/Scene.h"

namespace snell::cli {

// A probe's render: its milliseconds and rays.
using ProbeRender = std::function<std::pair<double, double>(const RenderRequest&)>;

// For the progress bar's time left: the time and the rays each region of
// the image costs, in the order the renderer finishes them, measured on a
// render of one pixel in 256 (every 16th row and column of the same image),
// region by region (a window once, whatever the regions that share it),
// costing about 1/256 of the render (Progress says which of the two it
// trusts). From 256² camera rays on: the image's size says little of the
// render's time (an amplifying scene at 1400² renders longer than a simple
// one at 8192²), and the probe's 16² or more pixels cost little. `render`
// returns its milliseconds and rays; `estimateMs` gains the probe's time.
// With `map`, also each probe pixel's rays (where the renderer counts them):
// the cost of the 16 × 16 pixels around it, by which the renderer weighs the
// pixels of the region in progress.
double estimateCost(const Scene& scene, const RenderRequest& request, const std::vector<RenderRegion>& regions,
                    Progress& progress, double& estimateMs, const ProbeRender& render, CostMap* map = nullptr);

// The CPU reference finishes rows top to bottom: its regions are bands of rows.
std::vector<RenderRegion> rowBands(const PixelWindow& area);

}  // namespace snell::cli
