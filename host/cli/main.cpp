// snell's command line: the only place that maps errors to exit statuses.
//   0 success · 1 runtime failure (Vulkan, files) · 2 bad scene or command line ·
//   128 + N ended by signal N (SIGINT 130, SIGHUP 129, SIGTERM 143)
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "gpu/ComputeRenderer.h"
#include "bench/Bench.h"
#include "common/Json.h"
#include "check/SceneCheck.h"
#include "preview/Preview.h"
#include "image/ImageIO.h"
#include "metrics/ImageMetrics.h"
#include "reference/CpuRenderer.h"
#include "scene/Parser.h"
#include "vulkan/VulkanContext.h"

#ifndef SNELL_VERSION
#define SNELL_VERSION "0.0.0"
#endif

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

constexpr int kExitRuntime = 1;
constexpr int kExitInput = 2;

// A termination signal asks the render to stop; the temporary output is
// removed and the status is the shell's convention for death by that signal.
std::atomic<bool> gInterrupted{false};
volatile std::sig_atomic_t gSignal = 0;
extern "C" void onSignal(int signal) {
    gSignal = signal;
    gInterrupted.store(true);
}
int interruptedStatus() { return 128 + (gSignal != 0 ? int(gSignal) : SIGINT); }

// The output's format comes from its extension; an unknown one is a command-line error.
const CLI::Validator kImageFormat(
    [](const std::string& path) {
        try {
            snell::formatForPath(path);
            return std::string();
        } catch (const snell::ImageIOError& e) {
            return std::string(e.what());
        }
    },
    "IMAGE");

// CLI11's Range lets NaN through (every comparison with it is false).
const CLI::Validator kFinite(
    [](const std::string& text) {
        const double value = std::strtod(text.c_str(), nullptr);
        return std::isfinite(value) ? std::string() : std::string("must be a finite number");
    },
    "FINITE");

const char* kExitStatuses =
    "Exit status: 0 success; 1 runtime failure (no Vulkan device, device lost, unwritable output);\n"
    "2 bad scene file or command line (the message is FILE:LINE:COL: error: ...); 128+N ended by signal N (Ctrl-C: 130).";

struct RenderOptions {
    std::string scene;
    std::string output;
    bool cpu = false;
    std::optional<int> size;
    std::optional<int> depth;
    std::optional<double> minWeight;
    std::optional<double> tolerance;
    std::optional<std::uint64_t> treeBudget;
    std::string boundImage;
    std::vector<int> region;  // X0 Y0 X1 Y1, or empty
    bool allowRunaway = false;
    std::optional<int> supersample;
    int gpu = -1;
    std::string precision = "fp32";
    bool stats = false;
    bool quiet = false;
    bool verbose = false;
    bool validation = false;
    snell::vk::FaultInjection fault;  // $SNELL_INJECT_FAULT, for tests
    std::uint32_t loopBudget = 0;     // $SNELL_LOOP_BUDGET, for tests
};

// A progress bar on stderr, only when stderr is a terminal: the pixels
// finished, the time so far, an estimate of the time left and the rays a
// second, a few times a second; erased when the render ends.
class Progress {
public:
    explicit Progress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)), start_(Clock::now()) {}
    std::function<void(double, std::uint64_t)> callback() {
        if (!enabled_) return {};
        return [this](double fraction, std::uint64_t rays) {
            std::lock_guard<std::mutex> lock(mutex_);
            if (!enabled_) return;
            const auto now = Clock::now();
            if (fraction < 1.0 && now - last_ < std::chrono::milliseconds(250)) return;
            last_ = now;
            shown_ = true;
            const double elapsed = std::chrono::duration<double>(now - start_).count();
            constexpr int kWidth = 24;
            const int filled = std::clamp(int(fraction * kWidth + 0.5), 0, kWidth);
            std::string line = "\rsnell: [" + std::string(filled, '#') + std::string(kWidth - filled, '.') + "] ";
            char text[160];
            std::snprintf(text, sizeof text, "%5.1f%%  %s elapsed", 100.0 * fraction, duration(elapsed).c_str());
            line += text;
            if (fraction > 0.01 && fraction < 1.0)
                line += ", ~" + duration(elapsed * (1.0 - fraction) / fraction) + " left";
            if (rays > 0 && elapsed > 0.0) {
                std::snprintf(text, sizeof text, ", %.3g Mrays/s", double(rays) / elapsed * 1e-6);
                line += text;
            }
            width_ = std::max(width_, line.size());
            std::fprintf(stderr, "%-*s", int(width_), line.c_str());
            std::fflush(stderr);
        };
    }
    // Erases the bar (before any message that follows the render).
    void done() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (shown_) std::fprintf(stderr, "\r%*s\r", int(width_), "");
        shown_ = false;
        enabled_ = false;
    }
    ~Progress() { done(); }

private:
    static std::string duration(double seconds) {
        char text[32];
        if (seconds < 60.0) std::snprintf(text, sizeof text, "%.1f s", seconds);
        else if (seconds < 3600.0) std::snprintf(text, sizeof text, "%d min %02d s", int(seconds / 60), int(seconds) % 60);
        else std::snprintf(text, sizeof text, "%d h %02d min", int(seconds / 3600), int(seconds / 60) % 60);
        return text;
    }
    bool enabled_;
    bool shown_ = false;
    std::size_t width_ = 0;
    std::mutex mutex_;
    Clock::time_point start_;
    Clock::time_point last_{};
};

// Where the render may still differ from the exact image (SPEC §4 limit):
// pixels whose dropped light has no finite bound, or whose tree was stopped.
void reportTruncation(const snell::TruncationReport& t, const snell::TraceSettings& settings) {
    // ", e.g. (x, y), ...", or nothing where the renderer kept no coordinates
    // (the GPU counts its over-budget pixels only).
    auto examples = [](const std::vector<std::array<int, 2>>& pixels, std::uint64_t count) {
        std::string s;
        for (const auto& p : pixels) s += (s.empty() ? "" : ", ") + ("(" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ")");
        if (s.empty()) return s;
        if (count > pixels.size()) s += ", ...";
        return ", e.g. " + s;
    };
    if (t.unbounded > t.estimated)
        std::cerr << "snell: warning: " << t.unbounded - t.estimated
                  << " pixel(s) dropped light of a material with ks + kt >= 1, which need not decay, and their "
                  << "colour had not settled at the floor cut-off: their bound is only the clamp to 1 "
                  << "(--bound-image shows it)" << examples(t.unboundedExamples, t.unbounded) << "\n";
    if (t.overBudget > 0)
        std::cerr << "snell: warning: " << t.overBudget << " pixel(s) reached the tree budget of "
                  << settings.treeBudget << " rays a sample and were stopped (their bound says by how much they "
                  << "may still move)" << examples(t.overBudgetExamples, t.overBudget) << "\n";
    if (t.overTolerance > t.unbounded)
        std::cerr << "snell: warning: " << t.overTolerance << " pixel(s) are above the tolerance "
                  << settings.tolerance << " at the floor cut-off " << settings.minWeight
                  << " (largest bound " << t.maxBound << ")\n";
}

std::string truncationJson(const snell::TruncationReport& t) {
    std::ostringstream j;
    j.precision(6);
    j << "{\"max_bound\": " << t.maxBound << ", \"mean_bound\": " << t.meanBound()
      << ", \"unbounded_pixels\": " << t.unbounded << ", \"over_budget_pixels\": " << t.overBudget
      << ", \"over_tolerance_pixels\": " << t.overTolerance << ", \"estimated_pixels\": " << t.estimated
      << ", \"max_estimated_error\": " << t.maxEstimate << ", \"deepest_ray\": " << t.deepest << "}";
    return j.str();
}

// Compiled pipelines persist here between runs: $SNELL_CACHE_DIR, else
// $XDG_CACHE_HOME/snell, else ~/.cache/snell; empty (no cache) if none is set.
std::string pipelineCachePath() {
    std::string dir;
    if (const char* d = std::getenv("SNELL_CACHE_DIR"); d && *d) dir = d;
    else if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) dir = std::string(x) + "/snell";
    else if (const char* h = std::getenv("HOME"); h && *h) dir = std::string(h) + "/.cache/snell";
    return dir.empty() ? std::string() : dir + "/pipelines.bin";
}

int runRender(const RenderOptions& o) {
    const auto totalStart = Clock::now();
    snell::Scene scene;
    const auto parseStart = Clock::now();
    try {
        scene = snell::parseSceneFile(o.scene);
    } catch (const snell::ParseError& e) {
        std::cerr << e.what() << "\n";
        return kExitInput;
    }
    const double parseMs = msSince(parseStart);
    if (!o.quiet)
        for (const snell::Diagnostic& w : scene.warnings) std::cerr << w.format("warning") << "\n";

    const std::string output = o.output.empty() ? scene.name + ".png" : o.output;
    try {
        snell::checkWritable(output);
    } catch (const snell::ImageIOError& e) {
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }

    snell::RenderRequest request;
    const int size = o.size.value_or(scene.imageSize);
    request.width = request.height = size;
    request.supersample = o.supersample.value_or(scene.supersample);
    request.camera = snell::Camera::fromSpec(size, scene.halfWidth);
    request.trace = o.cpu ? snell::kReferenceSettings : snell::kDefaultSettings;
    if (o.depth) request.trace.maxDepth = *o.depth;
    if (o.minWeight) request.trace.minWeight = *o.minWeight;
    // A depth or a cut-off without a tolerance asks for that tree, traced
    // once (POV-Ray's max_trace_level and adc_bailout); with a tolerance they
    // are its cap and floor.
    if ((o.depth || o.minWeight) && !o.tolerance) request.trace.tolerance = 0.0;
    if (o.tolerance) request.trace.tolerance = *o.tolerance;
    if (o.treeBudget) request.trace.treeBudget = *o.treeBudget;
    // No runaway trees: without a tree budget, the settings must bound each
    // sample's tree to a size that finishes (render/Truncation.h).
    if (request.trace.treeBudget == 0 && !o.allowRunaway) {
        constexpr double kMaxLog2Rays = 32;  // 4·10⁹ rays a sample
        const snell::TreeSizeBound tree =
            snell::treeSizeBound(scene, request.trace.maxDepth, request.trace.minWeight);
        if (tree.log2Rays > kMaxLog2Rays) {
            const snell::TextPosition at = scene.spheres[tree.sphere].location;
            std::ostringstream rays;
            rays << (std::isinf(tree.log2Rays) ? std::string("without bound") : "up to 2^" + std::to_string(int(tree.log2Rays)) + " rays");
            std::cerr << o.scene << ":" << at.line << ":" << at.column << ": error: the material of this sphere has "
                      << "ks + kt = " << tree.gain << " in a channel; with --depth " << request.trace.maxDepth
                      << ", --min-weight " << request.trace.minWeight << " and --tree-budget 0 a sample's ray tree "
                      << "can grow " << rays.str() << ", and the render may never end. Use --tree-budget "
                      << snell::kDefaultSettings.treeBudget << " (the default)";
            if (tree.gain <= 1.0) std::cerr << " or --min-weight " << snell::kDefaultSettings.minWeight;
            std::cerr << ", or --allow-runaway to trace it anyway\n";
            return kExitInput;
        }
    }
    snell::TruncationReport truncation;
    request.truncation = &truncation;
    std::vector<float> boundImage;
    if (!o.boundImage.empty()) request.boundImage = &boundImage;
    if (!o.region.empty()) {
        const snell::PixelWindow w{o.region[0], o.region[1], o.region[2], o.region[3]};
        if (w.x0 < 0 || w.y0 < 0 || w.x1 > size || w.y1 > size || w.empty()) {
            std::cerr << "snell: error: --region " << w.x0 << " " << w.y0 << " " << w.x1 << " " << w.y1
                      << " is not a window of the " << size << "x" << size
                      << " image (want 0 <= X0 < X1 <= " << size << ", 0 <= Y0 < Y1 <= " << size << ")\n";
            return kExitInput;
        }
        request.window = w;
    }
    const snell::PixelWindow area = request.area();
    request.cancel = &gInterrupted;
    Progress progress(!o.quiet);
    request.progress = progress.callback();

    // The image streams to a temporary file beside the output as bands of
    // rows finish; it replaces the output only when complete.
    std::unique_ptr<snell::ImageWriter> writer;
    double writeMs = 0.0;
    try {
        const std::string settings =
            "size " + std::to_string(size) + ", supersample " + std::to_string(request.supersample) + ", depth " +
            std::to_string(request.trace.maxDepth) + ", min-weight " + std::to_string(request.trace.minWeight) +
            ", " + (o.cpu ? "CPU reference" : "GPU " + o.precision);
        snell::ImageText text{{"Title", scene.name},
                              {"Source", o.scene},
                              {"Software", std::string("snell ") + SNELL_VERSION},
                              {"Comment", settings}};
        // A piece of a larger image says where it goes (`snell assemble`).
        if (!o.region.empty())
            text.push_back({"Region", std::to_string(area.x0) + " " + std::to_string(area.y0) + " of " +
                                          std::to_string(size) + "x" + std::to_string(size)});
        // EXR keeps the window as its data window within the whole image.
        const snell::ImagePlacement placement{area.x0, area.y0, size, size};
        writer = snell::ImageWriter::open(output, area.width(), area.height(), text, placement);
    } catch (const snell::ImageIOError& e) {
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
    std::string writeError;
    request.rowSink = [&](const float* rgb, int rows) {
        if (!writeError.empty()) return;
        const auto start = Clock::now();
        try {
            writer->writeRows(rgb, rows);
        } catch (const snell::ImageIOError& e) {
            writeError = e.what();
        }
        writeMs += msSince(start);
    };

    snell::RayCounts rays;
    double uploadMs = 0, pipelineMs = 0, renderMs = 0, readbackMs = 0;
    int tiles = 0, dispatches = 0;
    std::string device, timing;
    std::size_t trueSpheres = scene.spheres.size() - scene.ellipsoidCount();
    if (o.cpu) {
        const auto start = Clock::now();
        snell::CpuRenderer renderer(scene);
        renderer.render(request, &rays);
        renderMs = msSince(start) - writeMs;
        device = "CPU reference (double, " + std::to_string(std::max(1u, std::thread::hardware_concurrency())) + " threads)";
        timing = "host";
    } else {
        try {
            snell::vk::ContextOptions options;
            options.deviceIndex = o.gpu;
            options.validation = o.validation;
            options.fault = o.fault;
            options.pipelineCachePath = pipelineCachePath();
            snell::vk::Context context(options);
            device = context.deviceName();
            snell::ComputeRenderer renderer(
                context, scene, request.camera,
                o.precision == "fp64" ? snell::gpu::Precision::Fp64 : snell::gpu::Precision::Fp32);
            uploadMs = renderer.uploadMs();
            if (o.loopBudget > 0) renderer.forceLoopBudget(o.loopBudget);
            snell::GpuRenderResult r = renderer.render(request, o.stats);
            rays = r.rays;
            renderMs = r.renderMs;
            pipelineMs = r.pipelineMs;
            readbackMs = r.readbackMs;
            tiles = r.tiles;
            dispatches = r.dispatches;
            if (r.stackOverflows > 0 && !o.quiet)
                std::cerr << "snell: warning: " << r.stackOverflows << " ray(s) found their invocation's ray stack ("
                          << r.rayStack << " entries) full and were dropped (an amplifying tree); the truncation "
                          << "bound includes them. A higher --min-weight or a lower --depth keeps the tree smaller\n";
            timing = r.gpuTimed ? "gpu-timestamps" : "host";
            if (o.validation && context.validationMessages() > 0) {
                std::cerr << "snell: error: the Vulkan validation layer reported " << context.validationMessages()
                          << " message(s)\n";
                return kExitRuntime;
            }
        } catch (const snell::vk::VulkanError& e) {
            progress.done();
            if (gInterrupted.load()) {
                std::cerr << "snell: interrupted; no image written\n";
                return interruptedStatus();
            }
            std::cerr << "snell: error: " << e.what() << "\n";
            return kExitRuntime;
        }
    }
    progress.done();
    if (gInterrupted.load()) {
        std::cerr << "snell: interrupted; no image written\n";
        return interruptedStatus();
    }
    if (!writeError.empty()) {
        std::cerr << "snell: error: " << writeError << "\n";
        return kExitRuntime;
    }
    const auto commitStart = Clock::now();
    try {
        writer->commit();
    } catch (const snell::ImageIOError& e) {
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
    writeMs += msSince(commitStart);
    if (!o.boundImage.empty()) {
        // The bound as a grey image: float formats keep it as is.
        snell::Image bound(area.width(), area.height());
        for (std::size_t i = 0; i < boundImage.size(); ++i)
            bound.rgb[3 * i] = bound.rgb[3 * i + 1] = bound.rgb[3 * i + 2] = boundImage[i];
        try {
            snell::writeImage(o.boundImage, bound);
        } catch (const snell::ImageIOError& e) {
            std::cerr << "snell: error: " << e.what() << "\n";
            return kExitRuntime;
        }
    }
    if (!o.quiet) reportTruncation(truncation, request.trace);
    if (o.verbose) {
        std::fprintf(stderr,
                     "snell: %s: %dx%d, %s on %s\n"
                     "snell: parse %.1f ms, upload %.1f ms, pipeline %.1f ms, render %.1f ms (%s, %d tiles, %d "
                     "dispatches), readback %.1f ms, write %.1f ms; %.1f ms in all\n",
                     output.c_str(), request.width, request.height, o.cpu ? "CPU reference" : o.precision.c_str(),
                     device.c_str(), parseMs, uploadMs, pipelineMs, renderMs, timing.c_str(), tiles, dispatches,
                     readbackMs, writeMs, msSince(totalStart));
    }
    if (o.stats) {
        // With the image on standard output, the statistics go to standard error.
        std::ostream& statsOut = output == snell::kStandardOutput ? std::cerr : std::cout;
        std::ostringstream j;
        j.precision(6);
        j << std::fixed << "{\"scene\": " << snell::jsonString(o.scene) << ", \"output\": " << snell::jsonString(output)
          << ", \"backend\": \"" << (o.cpu ? "cpu" : "gpu") << "\", \"device\": " << snell::jsonString(device)
          << ", \"precision\": \"" << (o.cpu ? "fp64-reference" : o.precision) << "\""
          << ", \"width\": " << request.width << ", \"height\": " << request.height
          << ", \"supersample\": " << request.supersample << ", \"max_depth\": " << request.trace.maxDepth
          << ", \"min_weight\": " << request.trace.minWeight << ", \"spheres\": " << scene.spheres.size()
          << ", \"true_spheres\": " << trueSpheres << ", \"ellipsoids\": " << scene.ellipsoidCount()
          << ", \"lights\": " << scene.lights.size() << ", \"parse_ms\": " << parseMs
          << ", \"upload_ms\": " << uploadMs << ", \"pipeline_ms\": " << pipelineMs
          << ", \"render_ms\": " << renderMs << ", \"render_timing\": \"" << timing << "\""
          << ", \"tiles\": " << tiles << ", \"dispatches\": " << dispatches
          << ", \"readback_ms\": " << readbackMs << ", \"write_ms\": " << writeMs
          << ", \"total_ms\": " << msSince(totalStart) << ", \"rays\": {\"primary\": " << rays.primary
          << ", \"shadow\": " << rays.shadow << ", \"reflected\": " << rays.reflected
          << ", \"refracted\": " << rays.refracted << ", \"total\": " << rays.total() << "}"
          << ", \"tolerance\": " << request.trace.tolerance << ", \"truncation\": " << truncationJson(truncation)
          << "}";
        statsOut << j.str() << std::endl;
    }
    return 0;
}

// `snell assemble`: pieces rendered with --region into one image; every
// pixel must be covered. A piece is X,Y:FILE (its top-left pixel in the whole
// image), or an EXR FILE alone, placed by its data window. The pieces are
// pixels of the same render, so the result is the whole render, bit for bit.
int runAssemble(const std::string& output, const std::vector<std::string>& pieces, int size) {
    struct Piece {
        int x = 0, y = 0;
        snell::Image image;
    };
    std::vector<Piece> parsed;
    int width = 0, height = 0;
    for (const std::string& arg : pieces) {
        Piece p;
        const auto colon = arg.find(':');
        const auto comma = arg.find(',');
        const bool placed = colon != std::string::npos && comma != std::string::npos && comma < colon;
        const std::string file = placed ? arg.substr(colon + 1) : arg;
        if (placed) {
            char* end = nullptr;
            p.x = int(std::strtol(arg.c_str(), &end, 10));
            bool ok = end == arg.c_str() + comma;
            p.y = int(std::strtol(arg.c_str() + comma + 1, &end, 10));
            ok = ok && end == arg.c_str() + colon && p.x >= 0 && p.y >= 0;
            if (!ok) {
                std::cerr << "snell: error: a piece is X,Y:FILE (its top-left pixel, then the file), got '" << arg
                          << "'\n";
                return kExitInput;
            }
        }
        snell::ImagePlacement placement;
        try {
            p.image = snell::readImage(file, &placement);
        } catch (const std::exception& e) {
            std::cerr << "snell: error: " << e.what() << "\n";
            return kExitRuntime;
        }
        if (!placed) {
            if (!placement.stored) {
                std::cerr << "snell: error: '" << arg << "' does not say where it goes (only EXR keeps its "
                          << "window): give it as X,Y:FILE\n";
                return kExitInput;
            }
            if (placement.x < 0 || placement.y < 0) {
                std::cerr << "snell: error: '" << arg << "' lies outside its display window\n";
                return kExitInput;
            }
            p.x = placement.x;
            p.y = placement.y;
            // The whole image's size, from the display window, unless -s says it.
            if (size == 0) {
                width = std::max(width, placement.fullWidth);
                height = std::max(height, placement.fullHeight);
            }
        }
        width = std::max(width, p.x + p.image.width);
        height = std::max(height, p.y + p.image.height);
        parsed.push_back(std::move(p));
    }
    if (size > 0) {
        if (width > size || height > size) {
            std::cerr << "snell: error: the pieces reach " << width << "x" << height << ", beyond --size " << size << "\n";
            return kExitInput;
        }
        width = height = size;
    }
    snell::Image whole(width, height);
    std::vector<char> covered(std::size_t(width) * height, 0);
    for (const Piece& p : parsed) {
        for (int y = 0; y < p.image.height; ++y) {
            std::copy_n(p.image.pixel(0, y), std::size_t(p.image.width) * 3, whole.pixel(p.x, p.y + y));
            std::fill_n(covered.begin() + std::size_t(p.y + y) * width + p.x, p.image.width, 1);
        }
    }
    const auto missing = std::count(covered.begin(), covered.end(), 0);
    if (missing > 0) {
        std::cerr << "snell: error: the pieces leave " << missing << " of the " << width << "x" << height
                  << " pixels uncovered; nothing written\n";
        return kExitInput;
    }
    try {
        snell::writeImage(output, whole, {{"Software", std::string("snell ") + SNELL_VERSION + " assemble"}});
    } catch (const snell::ImageIOError& e) {
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
    return 0;
}

int runCompare(const std::string& a, const std::string& b, const std::string& diff, int threshold, bool json) {
    try {
        const snell::Image test = snell::readImage(a);
        const snell::Image reference = snell::readImage(b);
        const snell::ImageMetrics m = snell::compareImages(test, reference, threshold);
        if (!diff.empty()) snell::writeImage(diff, snell::differenceImage(test, reference));
        if (json) {
            std::cout << m.json() << std::endl;
        } else {
            std::printf("mean abs error %.4f/255, RMSE %.4f/255, PSNR %.2f dB, max %d/255\n"
                        "bad pixels (> %d/255) %llu of %llu (%.4f%%), isolated speckles %llu, NaN/Inf %llu\n",
                        m.meanAbsError, m.rmse, m.psnr, m.maxError, threshold,
                        static_cast<unsigned long long>(m.badPixels), static_cast<unsigned long long>(m.pixels),
                        100.0 * m.badFraction, static_cast<unsigned long long>(m.speckles),
                        static_cast<unsigned long long>(m.nonFinite));
        }
    } catch (const std::exception& e) {
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
    return 0;
}

int runPreviewCommand(const snell::PreviewOptions& o) {
    try {
        snell::runPreview(o);
    } catch (const snell::ParseError& e) {
        std::cerr << e.what() << "\n";
        return kExitInput;
    } catch (const snell::vk::VulkanError& e) {
        if (gInterrupted.load()) return interruptedStatus();
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    } catch (const std::runtime_error& e) {  // WindowError, ImageIOError
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
    return gInterrupted.load() ? interruptedStatus() : 0;
}

int runBenchCommand(snell::BenchOptions o) {
    namespace fs = std::filesystem;
    // The repository: the working directory when it has scenes/, else where snell was built from.
    if (o.sourceDir.empty()) o.sourceDir = fs::exists("scenes") && fs::exists("bench") ? "." : SNELL_SOURCE_DIR;
    if (o.sharedDir.empty()) o.sharedDir = (fs::path(o.sourceDir) / ".." / "shared").string();
    std::error_code ec;
    o.snellPath = fs::read_symlink("/proc/self/exe", ec).string();
    try {
        snell::runBench(o, std::cerr);
    } catch (const snell::ParseError& e) {
        std::cerr << e.what() << "\n";
        return kExitInput;
    } catch (const std::exception& e) {
        if (gInterrupted.load()) return interruptedStatus();
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
    return 0;
}

// Statistics on standard output, warnings on standard error; status 2 on errors.
int runCheck(const std::string& path, bool json) {
    snell::Scene scene;
    try {
        scene = snell::parseSceneFile(path);
    } catch (const snell::ParseError& e) {
        std::cerr << e.what() << "\n";
        return kExitInput;
    }
    const snell::SceneReport report = snell::checkScene(scene, path);
    for (const snell::Diagnostic& w : report.warnings) std::cerr << w.format("warning") << "\n";
    std::cout << (json ? report.json(scene) + "\n" : report.text(scene));
    return 0;
}

int runDevices() {
    try {
        const auto reports = snell::vk::Context::listDevices();
        if (reports.empty()) {
            std::cerr << "snell: no Vulkan device found: apt-get install mesa-vulkan-drivers\n";
            return kExitRuntime;
        }
        for (const auto& r : reports)
            std::cout << r.index << ": " << r.name << " (" << r.type << ", " << r.driver << ")"
                      << (r.usable ? "" : " — unusable: " + r.reason) << "\n";
    } catch (const snell::vk::VulkanError& e) {
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
    return 0;
}

std::string versionText() {
    std::string text = std::string("snell ") + SNELL_VERSION;
    try {
        snell::vk::Context context;
        text += "\ndevice: " + context.deviceName() + " (" + context.driverInfo() + ")";
    } catch (const snell::vk::VulkanError& e) {
        text += "\ndevice: none (" + std::string(e.what()) + ")";
    }
    return text;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"snell: a Whitted-style ray tracer whose renderer is a Vulkan compute shader.\n"
                 "Scene format: see README.md and SPEC.md.",
                 "snell"};
    app.footer(kExitStatuses);
    app.require_subcommand(0, 1);
    bool version = false;
    app.add_flag("--version", version, "Print the version and the Vulkan device snell would use");

    RenderOptions ro;
    CLI::App* render = app.add_subcommand("render", "Render a scene file to an image (PNG, PPM, PFM or EXR by extension)");
    render->add_option("scene", ro.scene, "Scene file")->required();
    render->add_option("-o,--output", ro.output, "Output image: .png, .ppm (P6), .pfm or .exr (float); - for PPM on standard output; default SCENE.png")
        ->check(kImageFormat);
    render->add_flag("--cpu", ro.cpu, "Render with the double-precision CPU reference instead of the GPU");
    render->add_option("-s,--size", ro.size, "Image size in pixels (overrides the scene's view n)")
        ->check(CLI::Range(1, snell::ParseLimits::kMaxImageSize));
    render->add_option("-d,--depth", ro.depth, "Maximum reflection/refraction depth; without --tolerance, a fixed tree of this depth traced once (default: 10000, a safety cap: the tolerance decides)")
        ->check(CLI::Range(0, 100000));
    render->add_option("--min-weight", ro.minWeight, "Stop rays whose weight falls below W; without --tolerance, a fixed tree traced once; with it, the lowest cut-off tried (default: GPU 1e-5, CPU 1e-7)")
        ->check(kFinite)->check(CLI::Range(0.0, 1.0));
    render->add_option("--tolerance", ro.tolerance,
                       "Trace each pixel until what its cut-offs may have lost is at most T (where no bound exists: until "
                       "its estimated error is); 0: a fixed tree (default: GPU 0.5/255 = 0.00196, exact in 8 bits; "
                       "CPU 0.01/255; 0 when --depth or --min-weight is given alone)")
        ->check(kFinite)->check(CLI::Range(0.0, 1.0));
    render->add_option("--tree-budget", ro.treeBudget,
                       "Stop a pixel's ray trees after N rays a sample and report the pixel; 0: no limit (default: 65536)")
        ->check(CLI::NonNegativeNumber);
    render->add_flag("--allow-runaway", ro.allowRunaway,
                     "Trace even when the settings allow a ray tree of astronomical size (no tree budget, and "
                     "amplifying materials or no cut-off): the render may never end");
    render->add_option("--bound-image", ro.boundImage,
                       "Also write each pixel's truncation bound (how far it may be from the exact image) to FILE "
                       "(.pfm or .exr keep it unclamped)")
        ->check(kImageFormat);
    render->add_option("--region", ro.region,
                       "Render only pixels X0..X1-1, Y0..Y1-1 of the image, as an image of that window (for a "
                       "render farm: join the pieces with 'snell assemble')")
        ->expected(4)->check(CLI::NonNegativeNumber);
    render->add_option("--spp,--supersample", ro.supersample, "Rays per pixel per axis (overrides the scene's supersample)")
        ->check(CLI::Range(1, snell::ParseLimits::kMaxSupersample));
    render->add_option("--gpu", ro.gpu, "Vulkan device index (see 'snell devices'; default: $SNELL_GPU, else the best)")
        ->envname("SNELL_GPU")->check(CLI::NonNegativeNumber);
    render->add_option("--precision", ro.precision,
                       "GPU arithmetic for geometry: fp32 (default) or fp64 (needs shaderFloat64; slower)")
        ->check(CLI::IsMember({"fp32", "fp64"}));
    render->add_flag("--stats", ro.stats, "Print timings and ray counts as one JSON object on the last line of stdout");
    render->add_flag("-q,--quiet", ro.quiet, "No warnings or progress on stderr");
    render->add_flag("-v,--verbose", ro.verbose, "Say on stderr which device rendered and where the time went");
    render->add_flag("--validation", ro.validation, "Enable the Khronos validation layer; any message fails the render")
        ->envname("SNELL_VALIDATION");

    snell::PreviewOptions po;
    std::string previewPrecision = "fp32";
    po.cancel = &gInterrupted;
    CLI::App* preview = app.add_subcommand("preview", "Show a scene in a window, live: orbit, inspect, hot reload");
    preview->footer(snell::kPreviewKeys);
    preview->add_option("scene", po.scene, "Scene file (re-rendered when saved)")->required();
    preview->add_option("-s,--size", po.size, "Rendered image size in pixels (default: the scene's view n)")
        ->check(CLI::Range(1, 4096));
    preview->add_option("-d,--depth", po.depth, "Initial maximum depth (default: 64)")->check(CLI::Range(0, 256));
    preview->add_option("--min-weight", po.minWeight, "Stop rays whose weight falls below W (default: 1e-4)")
        ->check(kFinite)->check(CLI::Range(0.0, 1.0));
    preview->add_option("--spp,--supersample", po.supersample, "Rays per pixel per axis when supersampling is on")
        ->check(CLI::Range(1, snell::ParseLimits::kMaxSupersample));
    preview->add_option("--gpu", po.gpu, "Vulkan device index (default: $SNELL_GPU, else the best)")
        ->envname("SNELL_GPU")->check(CLI::NonNegativeNumber);
    preview->add_option("--precision", previewPrecision, "GPU arithmetic for geometry: fp32 (default) or fp64")
        ->check(CLI::IsMember({"fp32", "fp64"}));
    preview->add_flag("--validation", po.validation, "Enable the Khronos validation layer")->envname("SNELL_VALIDATION");
    preview->add_flag("-q,--quiet", po.quiet, "No warnings or reload timings on stderr");
    CLI::Option* frames = preview->add_option("--frames", po.frames, "Scripted: show N frames, then save --screenshot and exit")
        ->check(CLI::PositiveNumber);
    preview->add_option("--screenshot", po.screenshot, "Scripted: the PNG to save after --frames frames")->needs(frames);
    preview->add_option("--orbit", po.orbitDegrees, "Scripted: orbit the camera by DEGREES before the first frame")
        ->check(kFinite);
    preview->add_option("--orbit-per-frame", po.orbitPerFrame,
                        "Scripted: orbit the camera by DEGREES before every frame, as a drag would (the moving camera)")
        ->check(kFinite)->needs(frames);

    snell::BenchOptions bo;
    bo.cancel = &gInterrupted;
    CLI::App* bench = app.add_subcommand("bench", "Speed against error: sweep settings, compare with peers, write CSV and JSON (bench/summarize.py: tables, plot)");
    bench->add_option("scenes", bo.scenes, "Scene files or directories (default: scenes/, scenes/hard/, the course and bench scenes)");
    bench->add_flag("--quick", bo.quick, "A small, fast run (CI): scenes/ and the bench scenes at 32x32, fewer settings");
    bench->add_option("-s,--size", bo.size, "Image size (default 128; quick 32)")->check(CLI::Range(8, 4096));
    bench->add_option("--runs", bo.runs, "Timed runs per setting after a warm-up (at least 5)")->check(CLI::Range(5, 1000));
    bench->add_option("-o,--out", bo.outDir, "Directory for bench.csv and bench.json (default bench/results)");
    bench->add_option("--source-dir", bo.sourceDir, "The snell repository (default: . if it has scenes/, else the build's)");
    bench->add_option("--shared-dir", bo.sharedDir, "Where course-scenes/ and bench-scenes/ are (default SOURCE/../shared)");
    bench->add_option("--gpu", bo.gpu, "Vulkan device index")->envname("SNELL_GPU")->check(CLI::NonNegativeNumber);

    std::string checkScene;
    bool checkJson = false;
    CLI::App* check = app.add_subcommand("check", "Parse a scene and report what it holds and what looks wrong, without rendering");
    check->add_option("scene", checkScene, "Scene file")->required();
    check->add_flag("--json", checkJson, "One JSON object on standard output");

    std::string compareA, compareB, compareDiff;
    int compareThreshold = 3;
    std::string assembleOutput;
    std::vector<std::string> assemblePieces;
    int assembleSize = 0;
    CLI::App* assemble = app.add_subcommand("assemble", "Join pieces rendered with render --region into one image");
    assemble->add_option("-o,--output", assembleOutput, "The whole image (.png, .ppm, .pfm or .exr)")
        ->required()->check(kImageFormat);
    assemble->add_option("pieces", assemblePieces, "Each piece as X,Y:FILE, X and Y its top-left pixel (X0 and Y0 "
                                                   "of its --region), or an EXR file alone (placed by its data "
                                                   "window)")->required();
    assemble->add_option("-s,--size", assembleSize, "The whole image's size, so a missing piece is an error "
                                                    "(default: the extent of the pieces)")
        ->check(CLI::Range(1, snell::ParseLimits::kMaxImageSize));
    CLI::App* compare = app.add_subcommand("compare", "Error metrics of image A against reference B (8-bit units): text, or --json");
    compare->add_option("a", compareA, "Test image")->required();
    compare->add_option("b", compareB, "Reference image")->required();
    compare->add_option("--diff", compareDiff, "Write a false-colour difference image");
    compare->add_option("--bad-threshold", compareThreshold, "A pixel is bad when a channel differs by more (default 3)");
    bool compareJson = false;
    compare->add_flag("--json", compareJson, "One JSON object instead of text");

    app.add_subcommand("devices", "List the Vulkan devices and why any cannot be used");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return kExitInput;
    }
    if (version) {
        std::cout << versionText() << "\n";
        return 0;
    }
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::signal(SIGHUP, onSignal);
    // A testing hook (docs/testing.md, "Faults and limits"): simulate a failing GPU.
    if (const char* fault = std::getenv("SNELL_INJECT_FAULT"); fault && *fault) {
        try {
            ro.fault = snell::vk::parseFaultInjection(fault);
        } catch (const std::invalid_argument& e) {
            std::cerr << "snell: error: SNELL_INJECT_FAULT: " << e.what() << "\n";
            return kExitInput;
        }
    }
    // Another: run the shader's suspend-and-resume path with this loop budget.
    if (const char* budget = std::getenv("SNELL_LOOP_BUDGET"); budget && *budget) {
        char* end = nullptr;
        const unsigned long value = std::strtoul(budget, &end, 10);
        if (*end != '\0' || value == 0 || value > SNELL_LOOP_BUDGET_LIMITED) {
            std::cerr << "snell: error: SNELL_LOOP_BUDGET: expected a loop budget from 1 to "
                      << SNELL_LOOP_BUDGET_LIMITED << ", not '" << budget << "'\n";
            return kExitInput;
        }
        ro.loopBudget = static_cast<std::uint32_t>(value);
    }
    if (render->parsed()) return runRender(ro);
    if (bench->parsed()) return runBenchCommand(bo);
    if (check->parsed()) return runCheck(checkScene, checkJson);
    if (preview->parsed()) {
        po.precision = previewPrecision == "fp64" ? snell::gpu::Precision::Fp64 : snell::gpu::Precision::Fp32;
        po.pipelineCachePath = pipelineCachePath();
        return runPreviewCommand(po);
    }
    if (app.got_subcommand("devices")) return runDevices();
    if (assemble->parsed()) return runAssemble(assembleOutput, assemblePieces, assembleSize);
    if (compare->parsed()) return runCompare(compareA, compareB, compareDiff, compareThreshold, compareJson);
    std::cout << app.help();
    return 0;
}
