// `snell render`: a scene to an image, on the GPU or with the CPU reference.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include "common/Clock.h"
#include "check/SceneCheck.h"
#include "cli/Command.h"
#include "cli/CostProbe.h"
#include "cli/ExitStatus.h"
#include "cli/Options.h"
#include "cli/Progress.h"
#include "cli/RenderReport.h"
#include "common/Json.h"
#include "gpu/ComputeRenderer.h"
#include "image/BackgroundWriter.h"
#include "image/BoundImage.h"
#include "image/ImageIO.h"
#include "reference/CpuRenderer.h"
#include "reference/CpuRetrace.h"
#include "render/TruncationMessages.h"
#include "scene/Parser.h"
#include "vulkan/VulkanContext.h"

#ifndef SNELL_VERSION
#define SNELL_VERSION "0.0.0"
#endif

namespace snell::cli {
namespace {


struct RenderOptions {
    std::string scene;
    std::string output;
    bool cpu = false;
    std::optional<int> size;
    TreeOptions tree;
    std::optional<double> tolerance;
    std::optional<std::uint64_t> treeBudget;
    std::string boundImage;
    std::string decisionMask;
    EncodingOptions encoding;
    std::vector<int> region;  // X0 Y0 X1 Y1, or empty
    bool allowRunaway = false;
    DeviceOptions device;
    bool stats = false;
    bool quiet = false;
    bool verbose = false;
    bool countLanes = false;
};

std::string truncationJson(const TruncationReport& t) {
    std::ostringstream j;
    j.precision(6);
    j << "{\"max_bound\": " << t.maxBound << ", \"mean_bound\": " << t.meanBound()
      << ", \"unbounded_pixels\": " << t.unbounded << ", \"over_budget_pixels\": " << t.overBudget
      << ", \"over_tolerance_pixels\": " << t.overTolerance << ", \"estimated_pixels\": " << t.estimated
      << ", \"dropped_growing_pixels\": " << t.droppedGrowing << ", \"undecided_pixels\": " << t.undecided
      << ", \"retraced_pixels\": " << t.retraced << ", \"retraced_samples\": " << t.retracedSamples
      << ", \"max_estimated_error\": " << t.maxEstimate << ", \"deepest_ray\": " << t.deepest << "}";
    return j.str();
}

// What the bar's line says while the probe renders.
constexpr const char* kProbing = "rendering 1 pixel in 256 to estimate the time";

// Renders expected to take at least this many seconds are traced in
// interleaved tiles (RenderRequest::interleavedTiles).
constexpr double kInterleaveFrom = 2.0;

// The image streams to a temporary file beside the output as bands of rows
// finish, encoded on a thread of its own (BackgroundWriter) while the render
// goes on; it replaces the output only when complete (no lost output).
class OutputStream {
public:
    OutputStream(const std::string& path, const Scene& scene, const RenderOptions& o, const RenderRequest& request);
    // The RenderRequest's row sink; keeps the first error for commit().
    std::function<void(const float*, int)> sink();
    void commit();
    // Encode beside the render, where that is faster (see BackgroundWriter).
    void encodeBeside(bool cpuRenderer);
    double encodeMs() const { return writer_->encodeMs(); }    // spent encoding, mostly during the render
    double blockedMs() const { return writer_->blockedMs(); }  // the render's wait for it, and the wait after it
    bool beside() const { return beside_; }                    // encoded on a thread beside the render

private:
    std::unique_ptr<BackgroundWriter> writer_;
    ImageFormat format_;
    bool beside_ = false;
    std::string error_;
};

class RenderCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override;
    int run() override;

private:
    RenderRequest makeRequest(const Scene& scene) const;
    TraceSettings traceSettings() const;
    // The GPU's default ray trees: no tree asked for on the command line.
    bool defaultTree() const {
        return !o_.cpu && !o_.tree.depth && !o_.tree.minWeight && !o_.tolerance && !o_.treeBudget;
    }
    void refuseRunawayTrees(const Scene& scene, const TraceSettings& trace) const;
    void refuseGpuOptions() const;
    RenderOutcome renderOnCpu(const Scene& scene, RenderRequest& request, OutputStream& stream,
                              Progress& progress) const;
    RenderOutcome renderOnGpu(const Scene& scene, RenderRequest& request, OutputStream& stream,
                              Progress& progress) const;
    // The progress bar's probe of a GPU render (estimateCost): its expected
    // cost, and whether its tiles interleave.
    void estimateGpuCost(const Scene& scene, RenderRequest& request, ComputeRenderer& renderer, Progress& progress,
                         RenderOutcome& r, CostMap& expectedCost) const;
    void writeDecisionMask(const RenderRequest& request, const std::vector<float>& decisions) const;
    void writeBoundImage(const RenderRequest& request, const std::vector<float>& bound,
                         const std::vector<float>& estimate) const;
    std::string statsJson(const Scene& scene, const RenderRequest& request, const RenderOutcome& r,
                          const std::string& output, double parseMs, const OutputStream& stream, double totalMs) const;

    RenderOptions o_;
    TruncationReport truncation_;
};

CLI::App* RenderCommand::define(CLI::App& app) {
    CLI::App* c = app.add_subcommand("render", "Render a scene file to an image (PNG, PPM, PFM or EXR by extension)");
    c->add_option("scene", o_.scene, kSceneHelp)->required();
    c->add_option("-o,--output", o_.output,
                  "Output image: .png, .ppm (P6), .pfm or .exr (float); - for PPM (the only format there) on "
                  "standard output, refused where that is a terminal; default SCENE.png")
        ->check(kImageFormat);
    c->add_flag("--cpu", o_.cpu,
                "Render with the double-precision CPU reference instead of the GPU; the GPU's own options (--gpu, "
                "--precision, --traversal, --validation, --count-lanes) are refused with it, their environment "
                "variables ignored");
    c->add_option("-s,--size", o_.size, "Image size in pixels (overrides the scene's view n)")
        ->check(wholeNumber(1, ParseLimits::kMaxImageSize));
    addTreeOptions(*c, o_.tree,
                   {"Maximum reflection/refraction depth; without --tolerance, a fixed tree of this depth traced "
                    "once (default: 10000, a safety cap: the tolerance decides)",
                    "Stop rays whose weight falls below W; without --tolerance, a fixed tree traced once; with it, "
                    "the lowest cut-off tried (default: GPU 1e-5, CPU 1e-7)",
                    100000});
    c->add_option("--tolerance", o_.tolerance,
                  "Trace each pixel until what its cut-offs may have lost is at most T (where no bound exists: until "
                  "its estimated error is); 0: a fixed tree (default: GPU 0.5/255 = 0.00196, exact in 8 bits; "
                  "CPU 0.01/255; 0 when --depth or --min-weight is given alone)")
        ->check(number(0.0, 1.0));
    c->add_option("--tree-budget", o_.treeBudget,
                  "Stop a pixel's ray trees after N rays a sample and report the pixel; 0: no limit (default: 65536)")
        ->check(wholeNumber(0));
    c->add_flag("--allow-runaway", o_.allowRunaway,
                "Trace even when the settings allow a ray tree of astronomical size (no tree budget, and "
                "amplifying materials or no cut-off): the render may never end");
    c->add_option("--bound-image", o_.boundImage,
                  "Also write each pixel's truncation bound (how far it may be from the exact image) to FILE, for "
                  "compare --bound-image: a certified bound, or where a pixel has none (ks + kt >= 1) but its error "
                  "was estimated, minus that estimate (.pfm or .exr keep it exact; .png shows magnitudes)")
        ->check(kImageFormat);
    c->add_option("--decision-mask", o_.decisionMask,
                  "Also write where rounding could decide the image to FILE: black where every decision was clear, "
                  "grey where the GPU's float left one within its rounding and the CPU reference traced the pixel "
                  "again in double, white where one stayed so and the bound covers both outcomes")
        ->check(kImageFormat);
    addEncodingOptions(*c, o_.encoding);
    c->add_option("--region", o_.region,
                  "Render only pixels X0..X1-1, Y0..Y1-1 of the image, as an image of that window (for a "
                  "render farm: join the pieces with 'snell assemble')")
        ->expected(4)->check(wholeNumber(0, std::numeric_limits<int>::max()));
    addDeviceOptions(*c, o_.device);
    c->add_flag("--stats", o_.stats,
                "Print timings and ray counts as one JSON object on the last line of stdout (stderr with -o -)");
    c->add_flag("-q,--quiet", o_.quiet, "No warnings or progress on stderr");
    c->add_flag("-v,--verbose", o_.verbose, "Say on stderr which device rendered and where the time went");
    c->add_flag("--count-lanes", o_.countLanes,
                "Measure the kernel: count the SIMD lanes busy in each pass of the trace loop and of the BVH walk "
                "(slower; --stats and -v report them)");
    return c;
}

int RenderCommand::run() {
    const auto totalStart = Clock::now();
    if (o_.cpu) refuseGpuOptions();
    else o_.device.readEnvironment();
    const auto parseStart = Clock::now();
    const Scene scene = readScene(o_.scene, !o_.quiet);
    const double parseMs = msSince(parseStart);
    RenderRequest request = makeRequest(scene);
    if (!o_.quiet)
        for (const Diagnostic& w : sceneWarnings(scene, sceneFile(o_.scene),
                                                  {request.width, request.supersample, defaultTree(), request.trace, request.window}))
            std::cerr << w.format("warning") << "\n";

    // Every file written is checked before any work, so none fails after the render.
    const std::string output = o_.output.empty() ? scene.name + ".png" : o_.output;
    checkWritable(output);
    if (!o_.boundImage.empty()) checkWritable(o_.boundImage);
    if (!o_.decisionMask.empty()) checkWritable(o_.decisionMask);
    request.truncation = &truncation_;
    std::vector<float> bound, estimate;
    if (!o_.boundImage.empty()) {
        request.boundImage = &bound;
        request.estimateImage = &estimate;
    }
    std::vector<float> decisions;
    if (!o_.decisionMask.empty()) request.decisionImage = &decisions;
    request.cancel = interruptFlag();
    Progress progress(!o_.quiet);
    request.progress = progress.callback();
    OutputStream stream(output, scene, o_, request);
    request.rowSink = stream.sink();

    const RenderOutcome outcome =
        o_.cpu ? renderOnCpu(scene, request, stream, progress) : renderOnGpu(scene, request, stream, progress);
    progress.done();
    if (interrupted()) throw Interrupted("no image written");
    stream.commit();
    if (!o_.boundImage.empty()) writeBoundImage(request, bound, estimate);
    if (!o_.decisionMask.empty()) writeDecisionMask(request, decisions);

    if (!o_.quiet)
        for (const std::string& line : truncationMessages(truncation_, request.trace)) std::cerr << line << "\n";
    if (o_.verbose)
        printVerbose(output, request, outcome, o_.cpu ? "CPU reference" : o_.device.precision, parseMs,
                     {stream.encodeMs(), stream.blockedMs(), stream.beside()}, msSince(totalStart), o_.countLanes);
    if (o_.stats) {
        // With the image on standard output, the statistics go to standard error.
        std::ostream& out = output == kStandardOutput ? std::cerr : std::cout;
        out << statsJson(scene, request, outcome, output, parseMs, stream, msSince(totalStart))
            << std::endl;
    }
    return kExitSuccess;
}

// The options that choose how the GPU renders do nothing for the CPU
// reference: given with --cpu they are a mistake, refused rather than
// ignored. Their environment variables are standing preferences, not
// refused (and not read).
void RenderCommand::refuseGpuOptions() const {
    std::vector<std::string> given = o_.device.given();
    if (o_.countLanes) given.push_back("--count-lanes");
    if (given.empty()) return;
    std::string names;
    for (std::size_t i = 0; i < given.size(); ++i)
        names += (i == 0 ? "" : i + 1 == given.size() ? " and " : ", ") + given[i];
    throw InputError(names + (given.size() > 1 ? " apply" : " applies") +
                     " to GPU renders only, and --cpu renders with the CPU reference (double precision, on the "
                     "host's cores): drop " + (given.size() > 1 ? "them" : "it") + " or --cpu");
}

TraceSettings RenderCommand::traceSettings() const {
    TraceSettings trace = o_.cpu ? kReferenceSettings : kDefaultSettings;
    if (o_.tree.depth) trace.maxDepth = *o_.tree.depth;
    if (o_.tree.minWeight) trace.minWeight = *o_.tree.minWeight;
    // A depth or a cut-off without a tolerance asks for that tree, traced
    // once (POV-Ray's max_trace_level and adc_bailout); with a tolerance they
    // are its cap and floor.
    if ((o_.tree.depth || o_.tree.minWeight) && !o_.tolerance) trace.tolerance = 0.0;
    if (o_.tolerance) trace.tolerance = *o_.tolerance;
    if (o_.treeBudget) trace.treeBudget = *o_.treeBudget;
    return trace;
}

RenderRequest RenderCommand::makeRequest(const Scene& scene) const {
    RenderRequest request;
    const int size = o_.size.value_or(scene.imageSize);
    request.width = request.height = size;
    request.supersample = o_.tree.supersample.value_or(scene.supersample);
    request.camera = Camera::fromSpec(size, scene.halfWidth);
    request.trace = traceSettings();
    refuseRunawayTrees(scene, request.trace);
    if (!o_.region.empty()) {
        const PixelWindow w{o_.region[0], o_.region[1], o_.region[2], o_.region[3]};
        if (w.x0 < 0 || w.y0 < 0 || w.x1 > size || w.y1 > size || w.empty())
            throw InputError("--region " + std::to_string(w.x0) + " " + std::to_string(w.y0) + " " +
                             std::to_string(w.x1) + " " + std::to_string(w.y1) + " is not a window of the " +
                             std::to_string(size) + "x" + std::to_string(size) + " image (want 0 <= X0 < X1 <= " +
                             std::to_string(size) + ", 0 <= Y0 < Y1 <= " + std::to_string(size) + ")");
        request.window = w;
    }
    return request;
}

// No runaway trees: without a tree budget, the settings must bound each
// sample's tree to a size that finishes (render/Truncation.h).
void RenderCommand::refuseRunawayTrees(const Scene& scene, const TraceSettings& trace) const {
    constexpr double kMaxLog2Rays = 32;  // 4·10⁹ rays a sample
    if (trace.treeBudget != 0 || o_.allowRunaway) return;
    const TreeSizeBound tree = treeSizeBound(scene, trace.maxDepth, trace.minWeight);
    if (tree.log2Rays <= kMaxLog2Rays) return;
    std::ostringstream m;
    m << "the material of this sphere has ks + kt = " << tree.gain << " in a channel; with --depth " << trace.maxDepth
      << ", --min-weight " << trace.minWeight << " and --tree-budget 0 a sample's ray tree can grow "
      << (std::isinf(tree.log2Rays) ? std::string("without bound")
                                    : "up to 2^" + std::to_string(int(tree.log2Rays)) + " rays")
      << ", and the render may never end. Use --tree-budget " << kDefaultSettings.treeBudget << " (the default)";
    if (tree.gain <= 1.0) m << " or --min-weight " << kDefaultSettings.minWeight;
    m << ", or --allow-runaway to trace it anyway";
    const TextPosition at = scene.spheres[tree.sphere].location;
    throw ParseError(Diagnostic{{sceneFile(o_.scene), at.line, at.column}, m.str()});
}

RenderOutcome RenderCommand::renderOnCpu(const Scene& scene, RenderRequest& request, OutputStream& stream,
                                         Progress& progress) const {
    RenderOutcome r;
    CpuRenderer renderer(scene);
    stream.encodeBeside(true);
    if (progress.enabled())
        progress.during(kProbing, [&] {
            auto probe = [&](const RenderRequest& sparse) {
                const auto start = Clock::now();
                RayCounts rays;
                renderer.render(sparse, &rays);
                return std::pair(msSince(start), double(rays.total()));
            };
            estimateCost(scene, request, rowBands(request.area()), progress, r.estimateMs, probe);
        });
    progress.renderStarts();
    const auto start = Clock::now();
    renderer.render(request, &r.rays);
    r.renderMs = msSince(start) - stream.blockedMs();
    r.device = "CPU reference (double, " + std::to_string(std::max(1u, std::thread::hardware_concurrency())) +
               " threads)";
    return r;
}

void RenderCommand::estimateGpuCost(const Scene& scene, RenderRequest& request, ComputeRenderer& renderer,
                                    Progress& progress, RenderOutcome& r, CostMap& expectedCost) const {
    auto probe = [&](const RenderRequest& sparse) {
        const GpuRenderResult g = renderer.render(sparse, o_.stats);
        r.pipelineMs += g.pipelineMs;
        return std::pair(g.renderMs, double(g.tracedRays));
    };
    // A render long enough for its time left to matter is traced in
    // interleaved tiles (their probe is one sparse render of the whole); a
    // short one in blocks, which is cheaper on cheap scenes.
    const PixelWindow area = request.area();
    request.interleavedTiles = ComputeRenderer::interleaves(area);
    const double seconds = estimateCost(scene, request, ComputeRenderer::tiles(area, request.interleavedTiles),
                                        progress, r.estimateMs, probe, &expectedCost);
    if (request.interleavedTiles && seconds < kInterleaveFrom) {
        request.interleavedTiles = false;
        estimateCost(scene, request, ComputeRenderer::tiles(area, false), progress, r.estimateMs, probe, &expectedCost);
    }
}

RenderOutcome RenderCommand::renderOnGpu(const Scene& scene, RenderRequest& request, OutputStream& stream,
                                         Progress& progress) const {
    try {
        RenderOutcome r;
        vk::ContextOptions options = o_.device.context();
        options.fault = faultInjection();
        options.pipelineCachePath = pipelineCachePath();
        vk::Context context(options);
        stream.encodeBeside(context.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU);
        RendererOptions rendererOptions;
        rendererOptions.precision = o_.device.arithmetic();
        rendererOptions.traversal = o_.device.search();
        if (const std::uint32_t budget = loopBudgetOverride()) rendererOptions.loopBudget = budget;
        rendererOptions.decisions = decisionsKept();
        // Pixels whose float decisions stay undecided are traced again in
        // double by the CPU reference (docs/decisions.md).
        request.retrace = cpuRetrace(scene, request);
        rendererOptions.countLanes = o_.countLanes;
        ComputeRenderer renderer(context, scene, request.camera, rendererOptions);
        // The kernel first, compiled for a new scene structure (seconds on
        // lavapipe) and said so on the bar's line; the probe and the render
        // reuse it (the same specialisation), and neither's time counts it.
        const auto kernelStart = Clock::now();
        progress.during("compiling the kernel for this scene", [&] { renderer.prepare(request, o_.stats); });
        r.pipelineMs = msSince(kernelStart);
        r.kernelCached = !options.pipelineCachePath.empty();
        CostMap expectedCost;
        if (progress.enabled())
            progress.during(kProbing, [&] { estimateGpuCost(scene, request, renderer, progress, r, expectedCost); });
        progress.renderStarts();
        if (!expectedCost.empty()) request.expectedCost = &expectedCost;
        const GpuRenderResult g = renderer.render(request, o_.stats);
        request.expectedCost = nullptr;  // expectedCost ends here
        r.device = context.deviceName();
        r.traversal = renderer.traversal();
        r.kernel = renderer.kernelFolded() ? "folded" : "driver";
        r.kernelObject = renderer.kernelObject();
        r.uploadMs = renderer.uploadMs();
        r.rays = g.rays;
        r.renderMs = g.renderMs;
        r.pipelineMs += g.pipelineMs;
        r.readbackMs = g.readbackMs;
        r.tiles = g.tiles;
        r.interleaved = g.interleaved;
        r.dispatches = g.dispatches;
        r.invocations = g.invocations;
        r.lanes = g.lanes;
        r.timing = g.gpuTimed ? "gpu-timestamps" : "host";
        if (g.stackOverflows > 0 && !o_.quiet)
            std::cerr << "snell: warning: " << g.stackOverflows << " ray(s) found their invocation's ray stack ("
                      << g.rayStack << " entries) full and were dropped (an amplifying tree); the truncation "
                      << "bound includes them. A higher --min-weight or a lower --depth keeps the tree smaller\n";
        if (o_.device.validation && context.validationMessages() > 0)
            throw std::runtime_error("the Vulkan validation layer reported " +
                                     std::to_string(context.validationMessages()) + " message(s)");
        return r;
    } catch (const vk::VulkanError&) {
        if (interrupted()) throw Interrupted("no image written");
        throw;
    }
}

void RenderCommand::writeDecisionMask(const RenderRequest& request, const std::vector<float>& decisions) const {
    const PixelWindow area = request.area();
    Image mask(area.width(), area.height());
    for (std::size_t i = 0; i < decisions.size(); ++i)
        for (int k = 0; k < 3; ++k) mask.rgb[i * 3 + k] = 0.5f * decisions[i];  // 0, 1 or 2
    writeImage(o_.decisionMask, mask);
}

void RenderCommand::writeBoundImage(const RenderRequest& request, const std::vector<float>& bound,
                                    const std::vector<float>& estimate) const {
    const PixelWindow area = request.area();
    snell::writeBoundImage(o_.boundImage, area.width(), area.height(), bound, estimate,
                           {area.x0, area.y0, request.width, request.height}, o_.encoding.exr());
}

std::string RenderCommand::statsJson(const Scene& scene, const RenderRequest& request, const RenderOutcome& r,
                                     const std::string& output, double parseMs, const OutputStream& stream,
                                     double totalMs) const {
    std::ostringstream j;
    j.precision(6);
    j << std::fixed << "{\"scene\": " << jsonString(o_.scene) << ", \"output\": " << jsonString(output)
      << ", \"backend\": \"" << (o_.cpu ? "cpu" : "gpu") << "\", \"device\": " << jsonString(r.device)
      << ", \"precision\": \"" << (o_.cpu ? "fp64-reference" : o_.device.precision) << "\""
      << ", \"traversal\": \"" << r.traversal << "\""
      << ", \"kernel\": \"" << r.kernel << "\", \"kernel_object\": \"" << r.kernelObject << "\""
      << ", \"width\": " << request.width << ", \"height\": " << request.height
      << ", \"supersample\": " << request.supersample << ", \"max_depth\": " << request.trace.maxDepth
      << ", \"min_weight\": " << exactNumber(request.trace.minWeight) << ", \"spheres\": " << scene.spheres.size()
      << ", \"true_spheres\": " << scene.spheres.size() - scene.ellipsoidCount()
      << ", \"ellipsoids\": " << scene.ellipsoidCount() << ", \"lights\": " << scene.lights.size()
      << ", \"parse_ms\": " << parseMs << ", \"upload_ms\": " << r.uploadMs << ", \"pipeline_ms\": " << r.pipelineMs
      << ", \"render_ms\": " << r.renderMs << ", \"render_timing\": \"" << r.timing << "\""
      << ", \"tiles\": " << r.tiles << ", \"interleaved_tiles\": " << (r.interleaved ? "true" : "false")
      << ", \"dispatches\": " << r.dispatches << ", \"invocations\": " << r.invocations << ", \"readback_ms\": " << r.readbackMs
      << ", \"write_ms\": " << stream.encodeMs() << ", \"write_wait_ms\": " << stream.blockedMs()
      << ", \"total_ms\": " << totalMs
      << ", \"rays\": {\"primary\": " << r.rays.primary << ", \"shadow\": " << r.rays.shadow
      << ", \"reflected\": " << r.rays.reflected << ", \"refracted\": " << r.rays.refracted
      << ", \"total\": " << r.rays.total() << "}"
      << ", \"tolerance\": " << exactNumber(request.trace.tolerance)
      << ", \"truncation\": " << truncationJson(truncation_);
    if (o_.countLanes && !o_.cpu)
        j << ", \"lanes\": {\"trace_slots\": " << r.lanes.traceSlots << ", \"trace_busy\": " << r.lanes.traceBusy
          << ", \"trace_occupancy\": " << share(r.lanes.traceBusy, r.lanes.traceSlots)
          << ", \"walk_slots\": " << r.lanes.walkSlots << ", \"walk_busy\": " << r.lanes.walkBusy
          << ", \"walk_occupancy\": " << share(r.lanes.walkBusy, r.lanes.walkSlots) << "}";
    j << "}";
    return j.str();
}

OutputStream::OutputStream(const std::string& path, const Scene& scene, const RenderOptions& o,
                           const RenderRequest& request) {
    const PixelWindow area = request.area();
    const std::string settings =
        "size " + std::to_string(request.width) + ", supersample " + std::to_string(request.supersample) +
        ", depth " + std::to_string(request.trace.maxDepth) + ", min-weight " +
        exactNumber(request.trace.minWeight) + ", " + (o.cpu ? "CPU reference" : "GPU " + o.device.precision);
    ImageText text{{"Title", scene.name},
                   {"Source", sceneFile(o.scene)},
                   {"Software", std::string("snell ") + SNELL_VERSION},
                   {"Comment", settings}};
    // A piece of a larger image says where it goes (`snell assemble`).
    if (!o.region.empty())
        text.push_back({"Region", std::to_string(area.x0) + " " + std::to_string(area.y0) + " of " +
                                      std::to_string(request.width) + "x" + std::to_string(request.height)});
    // EXR keeps the window as its data window within the whole image.
    const ImagePlacement placement{area.x0, area.y0, request.width, request.height};
    // A few bands of rows may wait for the encoder: the render never waits
    // for it unless the encoder is slower, and memory stays bounded.
    constexpr int kQueuedRows = 1024;
    format_ = formatForPath(path);
    writer_ = std::make_unique<BackgroundWriter>(ImageWriter::open(path, area.width(), area.height(), text, placement,
                                                                   o.encoding.exr()),
                                                 area.width(), kQueuedRows);
}

std::function<void(const float*, int)> OutputStream::sink() {
    return [this](const float* rgb, int rows) {
        if (!error_.empty()) return;
        try {
            writer_->writeRows(rgb, rows);
        } catch (const ImageIOError& e) {
            error_ = e.what();
        }
    };
}

void OutputStream::encodeBeside(bool cpuRenderer) {
    // Measured on lavapipe (2 cores): a thread that encodes EXR beside the
    // render saves more than it slows the render; one that encodes PNG slows
    // it more than it saves. A GPU leaves the cores to the encoder.
    beside_ = !cpuRenderer || format_ == ImageFormat::Exr;
    if (beside_) writer_->start();
}

void OutputStream::commit() {
    if (!error_.empty()) throw ImageIOError(error_);
    writer_->commit();
}

}  // namespace

std::unique_ptr<Command> makeRenderCommand() { return std::make_unique<RenderCommand>(); }

}  // namespace snell::cli
