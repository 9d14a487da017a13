// What a render is asked to do and what it counts, whichever back end does
// it: the CPU reference (host/reference) or the compute shader (host/gpu).
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "render/Truncation.h"
#include "scene/Scene.h"

namespace snell {

struct TraceSettings {
    int maxDepth = 64;          // reflection/refraction generations below the primary ray
    double minWeight = 1e-7;    // Hall & Greenberg cut-off on a ray's weight; 0 turns it off
    // Inspection switches (the preview's keys): off, shadow rays are not cast
    // (every light is seen), or reflected / refracted rays are not spawned.
    bool shadows = true;
    bool reflection = true;
    bool refraction = true;
    // > 0: trace each pixel until its truncation bound (render/Truncation.h) is
    // at most this. The cut-off steps down a ladder of powers of two
    // (kFirstRung), each step continuing from the rays the last one left under
    // its cut-off, down to minWeight, which is then the floor rather than the
    // cut-off. 0: one tree with the fixed cut-off minWeight and depth limit
    // maxDepth.
    double tolerance = 0.0;
    // With a tolerance, a pixel that cannot be certified (light dropped where
    // it need not decay, R = +inf) stops once its estimated error (the change
    // of its last step, extrapolated as a geometric series) is within the
    // tolerance; off, it goes on to the floor.
    bool estimate = false;
    // The most rays (closest-hit queries) a pixel's trees may trace, per
    // sample, before the pixel is stopped and reported over budget; 0: no
    // limit. Amplifying trees (SPEC §4) can grow without end; this keeps a
    // render finite.
    std::uint64_t treeBudget = 0;
};

// The exact image (SPEC §4, the limit of the ray tree) as far as it can be
// certified: depth bounded only by weight (a safety cap far beyond any
// converged tree), each pixel traced until its truncation bound (or, where it
// has none, its estimated error) is below 1/100 of an 8-bit step, and a tree
// budget that keeps amplifying trees finite.
inline constexpr TraceSettings kReferenceSettings{.maxDepth = 10000,
                                                  .minWeight = 1e-7,
                                                  .tolerance = 0.01 / 255.0,
                                                  .estimate = true,
                                                  .treeBudget = std::uint64_t(1) << 16};
// What `snell render` uses unless told otherwise (docs/design.md, "Defaults"):
// each pixel certified within half an 8-bit step where the scene allows it,
// else stopped by its estimated error; cut-offs no lower than 1e-5; trees of
// amplifying scenes bounded.
inline constexpr TraceSettings kDefaultSettings{.maxDepth = 10000,
                                                .minWeight = 1e-5,
                                                .tolerance = 0.5 / 255.0,
                                                .estimate = true,
                                                .treeBudget = std::uint64_t(1) << 16};
// The preview's, for frames in tens of milliseconds: a fixed depth and cut-off.
inline constexpr TraceSettings kPreviewSettings{.maxDepth = 64, .minWeight = 1e-4};

// The cut-offs a tolerance tries are rungs 2^-k of one ladder, from kFirstRung
// down, each set by the tree alone, whatever the tolerance: each step traces on
// from the rays the last one left, so the tree at a rung is the same however
// it was reached, and a looser tolerance stops on the same rung or a higher
// one: it never traces more.
inline constexpr double kFirstRung = 0.25;
// A step goes kRungsDown rungs of 2 below the heaviest ray the last one left
// (a factor of 16 in weight): a step costs more than a pixel's few extra rays
// (each step re-reads the rays it leaves waiting), so fewer, deeper steps are
// the cheaper way to the same accuracy (docs/performance.md, "The price of
// the default"). trace.comp steps the same.
inline constexpr int kRungsDown = 4;
inline double cutOffRung(double weight) {  // the highest rung <= weight (weight > 0)
    int exponent = 0;
    std::frexp(weight, &exponent);  // weight = m · 2^exponent, m in [1/2, 1)
    return std::ldexp(0.5, exponent);
}
inline double nextRung(double heaviestLeft) { return std::ldexp(cutOffRung(heaviestLeft), -kRungsDown); }

struct RayCounts {
    std::uint64_t primary = 0;
    std::uint64_t shadow = 0;
    std::uint64_t reflected = 0;
    std::uint64_t refracted = 0;
    std::uint64_t total() const { return primary + shadow + reflected + refracted; }
};

// A window of an image: pixels [x0, x1) × [y0, y1).
struct PixelWindow {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    bool empty() const { return x1 <= x0 || y1 <= y0; }
    bool operator==(const PixelWindow&) const = default;
};

// A part of a render, as the progress bar's probe sees it (the regions of a
// render in the order its renderer finishes them): `share` of the pixels of
// `window`, spread evenly over it (a tile of every other row and column of
// the window is a quarter of it; a block of rows, the whole of its window).
struct RenderRegion {
    PixelWindow window;
    double share = 1.0;
};

// What each pixel of an image is expected to cost, on a grid `stride` times
// coarser than the image (a cell per stride × stride pixels): the progress
// bar's sparse render.
struct CostMap {
    int stride = 1, width = 0, height = 0;
    std::vector<float> cells;  // row-major, width × height
    bool empty() const { return cells.empty(); }
    float at(int x, int y) const {
        return cells[std::size_t(std::min(y / stride, height - 1)) * width + std::min(x / stride, width - 1)];
    }
};

// A pixel the GPU's float decisions left undecided (render/Margins.h), handed
// to the CPU reference: where it is, and what the reference makes of it.
struct RetracedPixel {
    int x = 0, y = 0;
    std::uint64_t samples = 0;  // only these (bit k: sample firstSample + k); 0: all
    glm::dvec3 colour{0.0};     // their mean
    PixelTruncation truncation;
    double widening = 0.0;  // of the bound, on either side of the colour (CpuRenderer::Pixel)
    double gap = 0.0;       // the truncation bound before the clamp, largest channel
};

struct RenderRequest {
    Camera camera;
    int width = 0;
    int height = 0;
    // Render only this window of the width × height image (empty: all of
    // it). The image, its rows and the bound image are then the window's;
    // every pixel is computed exactly as in the whole image.
    PixelWindow window;
    PixelWindow area() const { return window.empty() ? PixelWindow{0, 0, width, height} : window; }
    int supersample = 1;
    // Of the supersample² rays per pixel (SPEC §3, row-major over the
    // sub-pixel grid), trace those from firstSample on, sampleCount of them
    // (0: all); the image is their mean. Progressive preview frames take one each.
    int firstSample = 0;
    int sampleCount = 0;
    // The samples each pixel traces: sampleCount of the grid from firstSample.
    int samplesTraced() const {
        const int grid = std::max(1, supersample) * std::max(1, supersample);
        const int first = std::clamp(firstSample, 0, grid - 1);
        return sampleCount > 0 ? std::min(sampleCount, grid - first) : grid - first;
    }
    TraceSettings trace;
    int threads = 0;  // 0: all hardware threads
    // Called now and then (from worker threads) with the fraction of pixels
    // finished and the rays traced so far.
    std::function<void(double fraction, std::uint64_t rays)> progress;
    // When set (GPU renderer), the fraction given to `progress` counts the
    // tile in progress by the share of its time done, as the renderer
    // forecasts it from the expected cost here of the pixels its workgroups
    // have finished and have left (render/WorkgroupSchedule.h), not by its
    // pixels finished (cheap ones finish first).
    const CostMap* expectedCost = nullptr;
    // GPU renderer: an image of a few tiles in interleaved tiles, each a fair
    // sample of the whole, so the first tile's time forecasts the others'
    // (ComputeRenderer::kMaxInterleavedSide); the image is the same.
    bool interleavedTiles = false;
    // Set to true from anywhere to stop early (the result is then incomplete).
    const std::atomic<bool>* cancel = nullptr;
    // When set, finished rows go here, top to bottom (width * 3 floats per
    // row), and the renderer keeps only a band of rows, not the whole image:
    // the returned image is then empty.
    std::function<void(const float* rgb, int rows)> rowSink;
    // When set, the truncation of the render is summed here (render/Truncation.h).
    TruncationReport* truncation = nullptr;
    // When set, each pixel's truncation bound, row-major (width * height).
    std::vector<float>* boundImage = nullptr;
    // When set, each pixel's estimated error where it has no finite bound and
    // one was made (PixelTruncation::estimatedError), else +inf, row-major.
    std::vector<float>* estimateImage = nullptr;
    // When set, each pixel's decisions (row-major): 0 decided, 1 re-traced by
    // the CPU reference where the GPU's were undecided, 2 undecided (widened).
    std::vector<float>* decisionImage = nullptr;
    // The renderers' part in the two: sized for `pixels`, then pixel `at`.
    void startTruncationImages(std::size_t pixels) const {
        if (boundImage) boundImage->assign(pixels, 0.0f);
        if (estimateImage) estimateImage->assign(pixels, std::numeric_limits<float>::infinity());
        if (decisionImage) decisionImage->assign(pixels, 0.0f);
    }
    void recordTruncation(std::size_t at, const PixelTruncation& p) const {
        if (boundImage) (*boundImage)[at] = float(p.bound);
        if (estimateImage)
            (*estimateImage)[at] = p.unbounded ? float(p.estimatedError) : std::numeric_limits<float>::infinity();
        if (decisionImage) (*decisionImage)[at] = p.undecided ? 2.0f : p.retraced ? 1.0f : 0.0f;
    }
    // When set (GPU renderer), the pixels whose decisions its float left
    // undecided beyond what their bound may take are traced again by this (the
    // CPU reference in double: reference/CpuRetrace.h), tile by tile; unset,
    // their bound is widened to cover both outcomes.
    std::function<void(std::vector<RetracedPixel>&)> retrace;
    // When set (GPU renderer), each pixel's rays (closest-hit queries of its
    // trees), row-major (width * height): its cost.
    std::vector<float>* rayImage = nullptr;
};

}  // namespace snell
