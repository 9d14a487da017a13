// What `snell render` did and where its time went, and the lines -v prints
// of it on standard error.
#pragma once

#include <string>

#include "gpu/GpuRenderResult.h"
#include "render/RenderRequest.h"

namespace snell::cli {

// What the renderer did, for --verbose and --stats.
struct RenderOutcome {
    RayCounts rays;
    std::string device;
    std::string traversal = "reference";  // ComputeRenderer::traversal() on the GPU
    std::string kernel = "reference";     // on the GPU: "folded" (its specialisation folded in) or "driver"
    std::string kernelObject = "none";    // on the GPU: ComputeRenderer::kernelObject()
    bool kernelCached = false;            // the kernel's binary kept in a cache directory (GPU)
    std::string timing = "host";  // how renderMs was measured
    double uploadMs = 0, pipelineMs = 0, renderMs = 0, readbackMs = 0;
    double estimateMs = 0;  // the progress bar's sparse render (estimateCost)
    int tiles = 0, dispatches = 0;
    int invocations = 0;  // persistent invocations a dispatch (GPU)
    bool interleaved = false;  // interleaved tiles, else blocks (GPU)
    GpuRenderResult::Lanes lanes;
};

// How the image was encoded and written: on a thread beside the render, or
// on the render's own thread between its bands of rows.
struct WriteTimes {
    double encodeMs = 0.0;   // encoding and writing
    double blockedMs = 0.0;  // the render's wait for them
    bool beside = false;
};

// The -v lines: the image and device; then parse, upload, the kernel (where
// it came from), the progress bar's probe, the render, readback and write.
// `arithmetic`: "CPU reference", "fp32" or "fp64".
void printVerbose(const std::string& output, const RenderRequest& request, const RenderOutcome& r,
                  const std::string& arithmetic, double parseMs, const WriteTimes& write, double totalMs,
                  bool countLanes);

// part / whole, 0 where whole is 0.
inline double share(std::uint64_t part, std::uint64_t whole) { return whole ? double(part) / double(whole) : 0.0; }

// A setting as it is, in the shortest text that reads back as the same
// double (1e-07, 3.9215686274509805e-05), never rounded to "0.000000".
std::string exactNumber(double value);

// "1 tile", "4 tiles".
std::string counted(long long count, const std::string& noun);

}  // namespace snell::cli
