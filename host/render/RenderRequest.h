// What a render is asked to do and what it counts, whichever back end does
// it: the CPU reference (host/reference) or the compute shader (host/gpu).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>

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
};

// The converged settings used to compute the exact image (SPEC §4).
inline constexpr TraceSettings kReferenceSettings{64, 1e-7, true, true, true};
// What `snell render` uses unless told otherwise (docs/design.md, "Defaults").
inline constexpr TraceSettings kDefaultSettings{64, 1e-4, true, true, true};

struct RayCounts {
    std::uint64_t primary = 0;
    std::uint64_t shadow = 0;
    std::uint64_t reflected = 0;
    std::uint64_t refracted = 0;
    std::uint64_t total() const { return primary + shadow + reflected + refracted; }
};

struct RenderRequest {
    Camera camera;
    int width = 0;
    int height = 0;
    int supersample = 1;
    // Of the supersample² rays per pixel (SPEC §3, row-major over the
    // sub-pixel grid), trace those from firstSample on, sampleCount of them
    // (0: all); the image is their mean. Progressive preview frames take one each.
    int firstSample = 0;
    int sampleCount = 0;
    TraceSettings trace;
    int threads = 0;  // 0: all hardware threads
    // Called now and then from worker threads with the fraction done.
    std::function<void(double)> progress;
    // Set to true from anywhere to stop early (the result is then incomplete).
    const std::atomic<bool>* cancel = nullptr;
    // When set, finished rows go here, top to bottom (width * 3 floats per
    // row), and the renderer keeps only a band of rows, not the whole image:
    // the returned image is then empty.
    std::function<void(const float* rgb, int rows)> rowSink;
};

}  // namespace snell
