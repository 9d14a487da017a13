#include "cli/RenderReport.h"

#include <algorithm>
#include <charconv>
#include <cstdio>

namespace snell::cli {
namespace {

std::string milliseconds(double ms) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f ms", ms);
    return text;
}

// Where the GPU's kernel came from, as far as snell can tell: a pipeline's
// compile may be served by the driver's own disk cache, unseen.
std::string kernelSource(const RenderOutcome& r) {
    if (r.kernelObject == "shader binary") return "from the cache";
    if (r.kernelObject == "shader object") return "compiled for this scene's structure, kept in the cache";
    return r.kernelCached ? "a pipeline, compiled unless the driver's or snell's cache held it"
                          : "a pipeline, compiled unless the driver's cache held it";
}

std::string renderPart(const RenderOutcome& r, bool gpu) {
    std::string s = "render " + milliseconds(r.renderMs) + " (timed by " +
                    (r.timing == "gpu-timestamps" ? "the GPU" : "the host");
    if (gpu)
        s += ", " + counted(r.tiles, r.interleaved ? "interleaved tile" : "tile") + ", " +
             counted(r.dispatches, "dispatch");
    return s + ")";
}

// Encoding beside the render overlaps it, but for the render's waits; on
// the render's thread all of it adds to the time.
std::string writePart(const WriteTimes& w) {
    if (!w.beside) return "write " + milliseconds(w.encodeMs) + " (on the render's thread, between bands of rows)";
    return "write " + milliseconds(w.encodeMs) + " (on a thread beside the render, which waited " +
           milliseconds(std::min(w.blockedMs, w.encodeMs)) + " for it)";
}

}  // namespace

std::string exactNumber(double value) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, value).ptr;
    return std::string(text, end);
}

std::string counted(long long count, const std::string& noun) {
    if (count == 1) return "1 " + noun;
    const bool sibilant = noun.ends_with("ch") || noun.ends_with("sh") || noun.ends_with("s") || noun.ends_with("x");
    return std::to_string(count) + " " + noun + (sibilant ? "es" : "s");
}

void printVerbose(const std::string& output, const RenderRequest& request, const RenderOutcome& r,
                  const std::string& arithmetic, double parseMs, const WriteTimes& write, double totalMs,
                  bool countLanes) {
    const bool gpu = arithmetic != "CPU reference";
    if (gpu)
        std::fprintf(stderr, "snell: %s: %dx%d, %s (%s) on %s\n", output.c_str(), request.width, request.height,
                     arithmetic.c_str(), r.traversal.c_str(), r.device.c_str());
    else
        std::fprintf(stderr, "snell: %s: %dx%d on the %s\n", output.c_str(), request.width, request.height,
                     r.device.c_str());
    std::string line = "parse " + milliseconds(parseMs);
    if (gpu)
        line += ", upload " + milliseconds(r.uploadMs) + ", kernel " + milliseconds(r.pipelineMs) + " (" +
                kernelSource(r) + ")";
    if (r.estimateMs > 0)
        line += ", time-left probe " + milliseconds(r.estimateMs) +
                " (1 pixel in 256, rendered first for the progress bar's time left)";
    line += ", " + renderPart(r, gpu);
    if (gpu) line += ", readback " + milliseconds(r.readbackMs);
    line += ", " + writePart(write) + "; " + milliseconds(totalMs) + " in all";
    std::fprintf(stderr, "snell: %s\n", line.c_str());
    if (countLanes && gpu)
        std::fprintf(stderr, "snell: lanes busy: trace loop %.1f %% of %llu slots, BVH walk %.1f %% of %llu\n",
                     100.0 * share(r.lanes.traceBusy, r.lanes.traceSlots),
                     static_cast<unsigned long long>(r.lanes.traceSlots),
                     100.0 * share(r.lanes.walkBusy, r.lanes.walkSlots),
                     static_cast<unsigned long long>(r.lanes.walkSlots));
}

}  // namespace snell::cli
