#include "bench/Bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <sys/resource.h>
#include <sys/wait.h>

#include "common/Clock.h"
#include "bench/PovExport.h"
#include "common/Json.h"
#include "gpu/ComputeRenderer.h"
#include "kernel_layout.h"
#include "metrics/ImageMetrics.h"
#include "ray_sphere_kernel_comp_spv.h"
#include "ray_sphere_kernel_matrix_comp_spv.h"
#include "store_kernel_comp_spv.h"
#include "bvh_walk_kernel_comp_spv.h"
#include "gpu/GpuScene.h"
#include "reference/CpuRenderer.h"
#include "scene/Parser.h"
#include "scene/Transform.h"
#include "vulkan/ComputeKernel.h"
#include "vulkan/VulkanContext.h"

namespace snell {

namespace {

namespace fs = std::filesystem;

struct Stats {
    double median = 0.0, min = 0.0, max = 0.0;
};

Stats stats(std::vector<double> v) {
    if (v.empty()) return {};
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return {median, v.front(), v.back()};
}

std::string number(double v) {
    if (!std::isfinite(v)) return "null";
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}

// One setting of the sweep.
struct Setting {
    std::string name;
    gpu::Precision precision = gpu::Precision::Fp32;
    gpu::BvhMode bvh = gpu::BvhMode::Auto;
    int depth = kDefaultSettings.maxDepth;
    double minWeight = kDefaultSettings.minWeight;
    double tolerance = kDefaultSettings.tolerance;  // 0: a fixed cut-off
    int supersample = 0;  // 0: the scene's
    bool front = false;   // one of the fixed trees the default is priced against (fixedSweep)
};

struct Result {
    std::string scene, group;
    Setting setting;
    int size = 0, spheres = 0, supersample = 1;
    bool bvhUsed = false;
    Stats dispatchMs;
    bool gpuTimed = false;
    RayCounts rays;
    ImageMetrics error;
    TruncationReport bound;  // the error the render states (render/Truncation.h)
    std::string failure;  // the renderer refused or failed: no numbers
};

struct Peer {
    std::string scene;
    int size = 0;
    double snellDispatchMs = 0.0, snellCommandMs = 0.0, coldMs = 0.0, warmMs = 0.0, cpuMs = 0.0;
    std::optional<double> povTraceMs, povCommandMs;
    std::string povNote;
};

struct Scaling {
    int spheres = 0;
    double parseMs = 0.0, bvhBuildMs = 0.0, uploadMs = 0.0;
    Stats renderMs;
    double gpuMiB = 0.0, peakRssMiB = 0.0;
    int size = 0;
};

double peakRssMiB() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss / 1024.0;
}

// Runs a command (through the shell), returning its wall time in ms and its
// output; throws when it cannot run or fails.
double runCommand(const std::string& command, std::string* output = nullptr) {
    const auto start = Clock::now();
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (!pipe) throw BenchError("cannot run: " + command);
    std::string text;
    char buffer[4096];
    while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) text.append(buffer, n);
    const int status = ::pclose(pipe);
    const double ms = msSince(start);
    if (output) *output = text;
    if (status != 0)
        throw BenchError("command failed (status " + std::to_string(WEXITSTATUS(status)) + "): " + command + "\n" +
                         text.substr(0, 2000));
    return ms;
}

std::string quote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

// The device's ceiling: ray–sphere tests per second of the micro-kernel; and
// its floor: a dispatch that only stores a pixel per invocation, against the
// renderer on a scene with nothing in it, at the same size.
struct Ceiling {
    double centreRadius = 0.0, matrix = 0.0;  // tests per second
    int floorSize = 0;                         // pixels a side
    double storeMs = 0.0, emptySceneMs = 0.0;  // median dispatch times
};

Ceiling measureCeiling(vk::Context& context, int runs, bool quick) {
    std::vector<gpu::CeilingSphere> spheres(SNELL_CEILING_SPHERES);
    for (int k = 0; k < SNELL_CEILING_SPHERES; ++k) {
        const dvec3 centre(-1.5 + 3.0 * (k % 8) / 7.0, -1.5 + 3.0 * (k / 8) / 7.0, -4.0 - 0.01 * k);
        spheres[k].centreRadius = glm::vec4(glm::vec3(centre), 0.15f);
        Transform t;
        t.translate(centre);
        t.scale(dvec3(0.15, 0.1, 0.2));
        spheres[k].objectFromWorld = glm::mat4(t.objectFromWorld());
    }
    const std::uint32_t rays = quick ? (1u << 18) : (1u << 20);
    vk::Buffer input = context.createBufferWithData(spheres.data(), spheres.size() * sizeof spheres[0],
                                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::Buffer output = context.createBuffer(rays * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Context::Memory::Device);
    Ceiling c;
    try {
        for (int form = 0; form < 2; ++form) {
            vk::ComputeKernel kernel(context, form == 0 ? snell_ray_sphere_kernel_comp_spv : snell_ray_sphere_kernel_matrix_comp_spv,
                                     form == 0 ? sizeof snell_ray_sphere_kernel_comp_spv : sizeof snell_ray_sphere_kernel_matrix_comp_spv,
                                     2);
            const std::uint32_t groups = rays / SNELL_KERNEL_GROUP_SIZE;
            kernel.run({&input, &output}, nullptr, groups);  // warm-up (llvmpipe compiles here)
            std::vector<double> ms;
            for (int r = 0; r < runs; ++r) ms.push_back(kernel.run({&input, &output}, nullptr, groups));
            const double testsPerSecond = double(rays) * SNELL_CEILING_SPHERES / (stats(ms).median * 1e-3);
            (form == 0 ? c.centreRadius : c.matrix) = testsPerSecond;
        }
    } catch (...) {
        context.destroy(input);
        context.destroy(output);
        throw;
    }
    context.destroy(input);
    context.destroy(output);

    // The floor.
    c.floorSize = quick ? 256 : 1024;
    const std::uint32_t pixels = std::uint32_t(c.floorSize) * std::uint32_t(c.floorSize);
    vk::Buffer image = context.createBuffer(VkDeviceSize(pixels) * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Context::Memory::Device);
    try {
        vk::ComputeKernel kernel(context, snell_store_kernel_comp_spv, sizeof snell_store_kernel_comp_spv, 1);
        kernel.run({&image}, nullptr, pixels / SNELL_KERNEL_GROUP_SIZE);
        std::vector<double> ms;
        for (int r = 0; r < runs; ++r) ms.push_back(kernel.run({&image}, nullptr, pixels / SNELL_KERNEL_GROUP_SIZE));
        c.storeMs = stats(ms).median;
    } catch (...) {
        context.destroy(image);
        throw;
    }
    context.destroy(image);
    const Scene empty = parseScene("view " + std::to_string(c.floorSize) + " 0.5\nbackground 0.2 0.3 0.4\n", "empty.scn");
    RenderRequest request;
    request.width = request.height = c.floorSize;
    request.camera = Camera::fromSpec(c.floorSize, empty.halfWidth);
    ComputeRenderer renderer(context, empty, request.camera);
    renderer.render(request, false);
    std::vector<double> ms;
    for (int r = 0; r < runs; ++r) ms.push_back(renderer.render(request, false).renderMs);
    c.emptySceneMs = stats(ms).median;
    return c;
}


// The BVH walk's floor on one scene (shaders/bvh_walk_kernel.comp): its
// camera rays and their shadow rays walked with nothing else, beside the
// renderer casting the same rays (depth 0, no cut-off) at the same size.
// What the renderer costs above it is its own; what the floor costs is the
// walk's on this device.
struct WalkFloor {
    std::string scene;
    int size = 0;
    double floorMs = 0.0, renderMs = 0.0;         // median dispatch times
    std::uint64_t floorRays = 0, renderRays = 0;  // camera and shadow rays each cast
    std::uint64_t floorHits = 0, floorBlocked = 0;  // the kernel's camera rays that hit, shadow rays blocked
};

std::optional<WalkFloor> measureWalkFloor(vk::Context& context, const Scene& scene, const std::string& name,
                                          const RenderRequest& base, int runs) {
    RenderRequest request = base;
    request.supersample = 1;  // the kernel casts each pixel's centre
    request.trace.maxDepth = 0;
    request.trace.minWeight = 0.0;
    request.trace.tolerance = 0.0;
    const gpu::GpuScene layout = gpu::buildGpuScene(scene, request.camera);
    if (!layout.usesBvh()) return std::nullopt;
    WalkFloor w;
    w.scene = name;
    w.size = request.width;
    gpu::FrameParams frame = gpu::makeFrameParams(scene, layout, request);
    // Storage buffers may not be empty: a scene without ellipsoids or lights
    // binds one unused element.
    const std::vector<gpu::Ellipsoid> ellipsoids =
        layout.ellipsoids.empty() ? std::vector<gpu::Ellipsoid>(1) : layout.ellipsoids;
    const std::vector<gpu::Light> lights = layout.lights.empty() ? std::vector<gpu::Light>(1) : layout.lights;
    const std::uint32_t pixels = std::uint32_t(request.width) * std::uint32_t(request.height);
    constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    std::vector<vk::Buffer> buffers;
    buffers.reserve(6);  // push_back cannot throw and lose a buffer
    auto release = [&] {
        for (vk::Buffer& b : buffers) context.destroy(b);
    };
    try {
        vk::Buffer nodes = context.createBufferWithData(layout.nodes.data(), layout.nodes.size() * sizeof(gpu::BvhNode),
                                                        VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
        buffers.push_back(nodes);
        gpu::splitAddress(context.deviceAddress(nodes), frame.bvhAddressLow, frame.bvhAddressHigh);
        buffers.push_back(context.createBufferWithData(&frame, sizeof frame, storage));
        buffers.push_back(context.createBufferWithData(layout.spheres.data(), layout.spheres.size() * sizeof(gpu::Sphere), storage));
        buffers.push_back(context.createBufferWithData(ellipsoids.data(), ellipsoids.size() * sizeof(gpu::Ellipsoid), storage));
        buffers.push_back(context.createBufferWithData(lights.data(), lights.size() * sizeof(gpu::Light), storage));
        buffers.push_back(context.createBuffer(VkDeviceSize(pixels) * 4 * sizeof(std::uint32_t), storage,
                                               vk::Context::Memory::HostCached));
        const auto stackSize = std::uint32_t(layout.bvhStackSize());
        vk::ComputeKernel kernel(context, snell_bvh_walk_kernel_comp_spv, sizeof snell_bvh_walk_kernel_comp_spv, 5,
                                 0, {stackSize, stackSize <= SNELL_REGISTER_STACK_LIMIT ? 1u : 0u});
        std::vector<const vk::Buffer*> bound;  // all but the nodes
        for (std::size_t k = 1; k < buffers.size(); ++k) bound.push_back(&buffers[k]);
        // Rows of at most 32768 workgroups (a device may allow no more than
        // 65535 in one dimension).
        const std::uint32_t groups = (pixels + SNELL_KERNEL_GROUP_SIZE - 1) / SNELL_KERNEL_GROUP_SIZE;
        const std::uint32_t groupsX = std::min(groups, 32768u);
        const std::uint32_t groupsY = (groups + groupsX - 1) / groupsX;
        kernel.run(bound, nullptr, groupsX, groupsY);  // warm-up (llvmpipe compiles here)
        std::vector<double> ms;
        for (int r = 0; r < runs; ++r) ms.push_back(kernel.run(bound, nullptr, groupsX, groupsY));
        w.floorMs = stats(ms).median;
        const auto* results = static_cast<const std::uint32_t*>(buffers.back().mapped);
        w.floorRays = pixels;
        for (std::uint32_t p = 0; p < pixels; ++p) {
            w.floorHits += results[4 * p] != 0xffffffffu ? 1 : 0;
            w.floorRays += results[4 * p + 1];
            w.floorBlocked += results[4 * p + 2];
        }
    } catch (...) {
        release();
        throw;
    }
    release();
    ComputeRenderer renderer(context, scene, request.camera);
    w.renderRays = renderer.render(request, true).rays.total();
    std::vector<double> ms;
    for (int r = 0; r < runs; ++r) ms.push_back(renderer.render(request, false).renderMs);
    w.renderMs = stats(ms).median;
    return w;
}

std::string describe(const WalkFloor& w) {
    const double floorRate = double(w.floorRays) / (w.floorMs * 1e-3);
    const double renderRate = double(w.renderRays) / (w.renderMs * 1e-3);
    std::ostringstream s;
    s << "walk floor at " << w.size << "x" << w.size << ", depth 0: kernel " << number(w.floorMs) << " ms ("
      << number(floorRate * 1e-6) << " Mrays/s), renderer " << number(w.renderMs) << " ms ("
      << number(renderRate * 1e-6) << " Mrays/s, " << number(w.renderMs / w.floorMs) << "x the floor)";
    if (w.floorRays != w.renderRays) s << "; rays " << w.floorRays << " against the renderer's " << w.renderRays;
    return s.str();
}

std::vector<Setting> settingsFor(const Scene& scene, bool quick, bool fp64) {
    std::vector<Setting> s;
    s.push_back({"default"});
    // Depth alone (no cut-off): at most 2^depth rays a pixel, so it stays small.
    const std::vector<int> depths = quick ? std::vector<int>{1, 5} : std::vector<int>{1, 2, 3, 5, 8};
    for (int d : depths) {
        Setting x{"depth " + std::to_string(d)};
        x.depth = d;
        x.minWeight = 0.0;
        x.tolerance = 0.0;
        s.push_back(x);
    }
    // The tolerance on each pixel's stated bound (the default is 0.5/255).
    for (double t : quick ? std::vector<double>{2.0} : std::vector<double>{8.0, 2.0, 0.1}) {
        std::ostringstream name;
        name << "tolerance " << t << "/255";
        Setting x{name.str()};
        x.tolerance = t / 255.0;
        s.push_back(x);
    }
    // The cut-off at full depth (0 is left out: a glass scene's tree then has 2^64 rays).
    const std::vector<double> weights = quick ? std::vector<double>{1e-2} : std::vector<double>{1e-2, 1e-3, 1e-5, 1e-7};
    for (double w : weights) {
        // Below the default cut-off an amplifying scene's tree (ks + kt > 1)
        // no longer shrinks with depth: 2^64 rays. Its sweep stops there.
        if (scene.anyAmplifying() && w < kDefaultSettings.minWeight) continue;
        std::ostringstream name;
        name << "min-weight " << w;
        Setting x{name.str()};
        x.minWeight = w;
        x.tolerance = 0.0;
        s.push_back(x);
    }
    // Where the device renders fp64 (Context::fp64Refusal).
    if (fp64) {
        Setting wide{"fp64"};
        wide.precision = gpu::Precision::Fp64;
        s.push_back(wide);
    }
    if (scene.spheres.size() > 1) {
        const bool autoUsesBvh = scene.spheres.size() > gpu::kBvhThreshold;
        Setting flip{autoUsesBvh ? "BVH off" : "BVH on"};
        flip.bvh = autoUsesBvh ? gpu::BvhMode::Off : gpu::BvhMode::On;
        s.push_back(flip);
    }
    if (scene.supersample > 1) {
        Setting one{"spp 1"};
        one.supersample = 1;
        s.push_back(one);
    }
    return s;
}


struct SceneFile {
    std::string path, group;
};

std::vector<SceneFile> collectScenes(const BenchOptions& o) {
    std::vector<SceneFile> out;
    auto addDir = [&](const fs::path& dir, const std::string& group) {
        std::vector<std::string> files;
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(dir, ec))
            if (e.path().extension() == ".scn") files.push_back(e.path().string());
        std::sort(files.begin(), files.end());
        for (const std::string& f : files) out.push_back({f, group});
    };
    if (!o.scenes.empty()) {
        for (const std::string& s : o.scenes) {
            if (fs::is_directory(s)) {
                const std::string dir = fs::path(s).lexically_normal().filename().string();
                addDir(s, dir == "bench-scenes" ? "bench" : dir == "course-scenes" ? "course" : dir);
            }
            else out.push_back({s, "given"});
        }
        return out;
    }
    addDir(fs::path(o.sourceDir) / "scenes", "scenes");
    if (!o.quick) {
        addDir(fs::path(o.sourceDir) / "scenes" / "hard", "hard");
        addDir(fs::path(o.sharedDir) / "course-scenes", "course");
    }
    addDir(fs::path(o.sharedDir) / "bench-scenes", "bench");
    return out;
}

// One scene at one size: the exact image every setting is measured against,
// and the renderers of its settings (one per precision and BVH mode).
struct SceneRun {
    vk::Context& context;
    const Scene& scene;
    std::string name, group;
    RenderRequest base;
    const Image& exact;
    int runs = 5;
    bool quick = false;  // a quick run (BenchOptions::quick)
    const std::atomic<bool>* cancel = nullptr;
    std::map<std::pair<int, int>, std::unique_ptr<ComputeRenderer>> renderers;

    // A warm-up, the timed renders (timedRuns) and one that counts the rays;
    // the error of the first timed image against the exact one.
    Result measure(const Setting& setting);
    // The dispatch times of settings a and b, rendered in turn in blocks
    // (kSideBySideRounds of a, then of b, each of `runs` timed renders after
    // an untimed one): side by side, so that a drift of the machine's speed
    // moves both alike. Not render by render: switching renderers at every
    // render evicts the other's data from the caches, which added 1 ms to a
    // 0.5 ms dispatch and so moved their ratio towards 1.
    std::pair<Stats, Stats> measureSideBySide(const Setting& a, const Setting& b, int runs);

    RenderRequest requestFor(const Setting& setting) const;
    ComputeRenderer& rendererFor(const Setting& setting);
};

// Timed renders of a setting whose warm-up took warmUpMs: at least `runs`,
// and for a cheap one as many as fill kTimedBudgetMs (at most kMaxTimedRuns):
// a median of five sub-millisecond dispatches moves by tens of per cent from
// run to run, and the price of the default is a ratio of two of them. Not in
// a quick run (CI), which checks what the bench reports, not its figures.
constexpr double kTimedBudgetMs = 200.0;
constexpr int kMaxTimedRuns = 101;
int timedRuns(int runs, double warmUpMs, bool quick) {
    if (quick || !(warmUpMs > 0.0)) return runs;
    return std::clamp(int(std::ceil(kTimedBudgetMs / warmUpMs)), runs, std::max(runs, kMaxTimedRuns));
}

RenderRequest SceneRun::requestFor(const Setting& setting) const {
    RenderRequest request = base;
    request.trace.maxDepth = setting.depth;
    request.trace.minWeight = setting.minWeight;
    request.trace.tolerance = setting.tolerance;
    if (setting.supersample) request.supersample = setting.supersample;
    return request;
}

ComputeRenderer& SceneRun::rendererFor(const Setting& setting) {
    auto& renderer = renderers[{int(setting.precision), int(setting.bvh)}];
    if (!renderer)
        renderer = std::make_unique<ComputeRenderer>(
            context, scene, base.camera, RendererOptions{.precision = setting.precision, .bvh = setting.bvh});
    return *renderer;
}

constexpr int kSideBySideRounds = 3;
std::pair<Stats, Stats> SceneRun::measureSideBySide(const Setting& a, const Setting& b, int runs) {
    const RenderRequest requestA = requestFor(a), requestB = requestFor(b);
    // A renderer each: one keeps one pipeline and its buffers, and a render
    // with another specialisation would re-create them.
    ComputeRenderer& rendererA = rendererFor(a);
    ComputeRenderer rendererB(context, scene, base.camera, RendererOptions{.precision = b.precision, .bvh = b.bvh});
    std::vector<double> msA, msB;
    auto block = [&](ComputeRenderer& renderer, const RenderRequest& request, std::vector<double>& ms) {
        renderer.render(request, false);
        for (int k = 0; k < runs; ++k) ms.push_back(renderer.render(request, false).renderMs);
    };
    for (int round = 0; round < kSideBySideRounds; ++round) {
        block(rendererA, requestA, msA);
        block(rendererB, requestB, msB);
    }
    return {stats(msA), stats(msB)};
}

Result SceneRun::measure(const Setting& setting) {
    Result r;
    r.scene = name;
    r.group = group;
    r.setting = setting;
    r.size = base.width;
    r.spheres = int(scene.spheres.size());
    RenderRequest request = requestFor(setting);
    request.truncation = &r.bound;
    r.supersample = request.supersample;
    try {
        ComputeRenderer& renderer = rendererFor(setting);
        r.bvhUsed = renderer.layout().usesBvh();
        const double warmUpMs = renderer.render(request, false).renderMs;  // and pipeline and first dispatch
        std::vector<double> ms;
        Image image;
        const int n = timedRuns(runs, warmUpMs, quick);
        for (int k = 0; k < n; ++k) {
            GpuRenderResult g = renderer.render(request, false);
            ms.push_back(g.renderMs);
            r.gpuTimed = g.gpuTimed;
            if (k == 0) image = std::move(g.image);
        }
        r.dispatchMs = stats(ms);
        r.rays = renderer.render(request, true).rays;
        r.error = compareImages(image, exact);
    } catch (const vk::VulkanError& e) {
        if (cancel && cancel->load()) throw;
        r.failure = e.what();
    }
    return r;
}

// The price of the default: what its certified trees cost against fixed
// trees (tolerance 0) that are as accurate, measured against the exact image:
// no larger mean error and no more pixels off by more than 3/255.
bool asAccurate(const Result& r, const Result& def) {
    return r.failure.empty() && r.error.meanAbsError <= def.error.meanAbsError &&
           r.error.badPixels <= def.error.badPixels;
}

// A fixed series stops after a tree slower than this many times the default
// (none later can set the price), and before a depth cap whose tree may hold
// more rays than kFixedRayLimit, or after one that traced more than
// kFixedRayRatio times the default's rays.
constexpr double kFixedTimeRatio = 4.0;
constexpr double kFixedRayLimit = 50e6;
constexpr double kFixedRayRatio = 4.0;

constexpr int kLastCutOff = 12, kLastCutOffQuick = 6;  // cut-offs 4^-1 .. 4^-k
constexpr int kLastDepth = 16, kLastDepthQuick = 5;     // depth caps 1 .. d

// Whether `s` is one of the fixed trees the default is priced against:
// a cut-off 4^-k at the default depth limit, or a depth cap without a
// cut-off, at the scene's precision, BVH and supersampling.
bool isFixedTree(const Setting& s, bool quick) {
    if (s.tolerance != 0.0 || s.precision != gpu::Precision::Fp32 || s.bvh != gpu::BvhMode::Auto || s.supersample)
        return false;
    if (s.minWeight == 0.0) return s.depth >= 1 && s.depth <= (quick ? kLastDepthQuick : kLastDepth);
    int exponent = 0;
    const double mantissa = std::frexp(s.minWeight, &exponent);  // 4^-k = 0.5 · 2^(1 - 2k)
    const int k = (1 - exponent) / 2;
    return s.depth == kDefaultSettings.maxDepth && mantissa == 0.5 && (1 - exponent) % 2 == 0 && k >= 1 &&
           k <= (quick ? kLastCutOffQuick : kLastCutOff);
}

Setting fixedSetting(const std::string& name, int depth, double minWeight) {
    Setting s{name};
    s.depth = depth;
    s.minWeight = minWeight;
    s.tolerance = 0.0;
    s.front = true;
    return s;
}

// The index of `setting`'s result among this scene's (from `first` on): one
// measured already with the same parameters (the named depth sweep), else
// measured now.
std::size_t measureOnce(SceneRun& run, std::vector<Result>& results, std::size_t first, const Setting& setting) {
    for (std::size_t i = first; i < results.size(); ++i) {
        Setting& s = results[i].setting;
        if (s.precision == setting.precision && s.bvh == setting.bvh && s.depth == setting.depth &&
            s.minWeight == setting.minWeight && s.tolerance == setting.tolerance &&
            s.supersample == setting.supersample) {
            s.front = true;
            return i;
        }
    }
    results.push_back(run.measure(setting));
    return results.size() - 1;
}

// One series of fixed trees, in order of growing cost: next(k, previous)
// gives the k-th setting (k = 1, 2, ...), or nothing where the series ends
// before it. The series also ends after a tree as accurate as the default
// (the later ones are slower), one slower than kFixedTimeRatio times the
// default, or one that failed. Adds the indices of the trees measured.
template <class Next>
void sweepSeries(SceneRun& run, std::vector<Result>& results, std::size_t def, Next next,
                 std::vector<std::size_t>& tried) {
    std::optional<std::size_t> previous;
    for (int k = 1;; ++k) {
        const std::optional<Setting> setting = next(k, previous ? &results[*previous] : nullptr);
        if (!setting) return;
        const std::size_t i = measureOnce(run, results, def, *setting);
        const Result& r = results[i];
        if (!r.failure.empty()) return;
        if (std::find(tried.begin(), tried.end(), i) == tried.end()) tried.push_back(i);
        if (asAccurate(r, results[def]) || r.dispatchMs.median > kFixedTimeRatio * results[def].dispatchMs.median)
            return;
        previous = i;
    }
}

// The fixed trees the default is priced against (isFixedTree): (a) weight
// cut-offs 4^-k at the default depth limit and tree budget, k = 1..12
// (quick: 1..6), and (b) depth caps d = 1..16 (quick: 1..5) without a
// cut-off. `def` is the index of the scene's default result, its first; the
// named settings that are fixed trees (depth caps) count without a cost
// limit, as they are measured anyway. Returns the indices of the trees
// measured, marked as the front.
std::vector<std::size_t> fixedSweep(SceneRun& run, std::vector<Result>& results, std::size_t def, bool quick) {
    std::vector<std::size_t> tried;
    for (std::size_t i = def; i < results.size(); ++i) {
        if (!isFixedTree(results[i].setting, quick) || !results[i].failure.empty()) continue;
        results[i].setting.front = true;
        tried.push_back(i);
    }
    const int lastCutOff = quick ? kLastCutOffQuick : kLastCutOff;
    sweepSeries(run, results, def, [&](int k, const Result*) -> std::optional<Setting> {
        if (k > lastCutOff) return std::nullopt;
        const double w = std::ldexp(1.0, -2 * k);
        std::ostringstream name;
        name.precision(3);
        name << "fixed min-weight " << w;
        return fixedSetting(name.str(), kDefaultSettings.maxDepth, w);
    }, tried);
    const int lastDepth = quick ? kLastDepthQuick : kLastDepth;
    const double samples = double(run.base.width) * run.base.height * run.base.supersample * run.base.supersample;
    const double defaultRays = double(results[def].rays.total());
    sweepSeries(run, results, def, [&](int d, const Result* previous) -> std::optional<Setting> {
        if (d > lastDepth) return std::nullopt;
        // Without a cut-off a branching scene's tree doubles with each level.
        if (std::exp2(treeSizeBound(run.scene, d, 0.0).log2Rays) * samples > kFixedRayLimit) return std::nullopt;
        if (previous && double(previous->rays.total()) > kFixedRayRatio * defaultRays) return std::nullopt;
        return fixedSetting("fixed depth " + std::to_string(d), d, 0.0);
    }, tried);
    return tried;
}

// What the default costs: its dispatch time over the fastest fixed tree's as
// accurate (asAccurate). Where no tree tried is, the price is below the
// default's time over the slowest tried's: an upper bound.
struct Price {
    std::string scene;
    double defaultMs = NAN, defaultMean = NAN;
    std::uint64_t defaultBad = 0;
    double price = NAN;  // NaN: no fixed tree measured
    bool upperBound = false;
    std::string fixed;  // the fixed tree that sets the price (or the bound)
    double fixedMs = NAN, fixedMean = NAN;
    std::uint64_t fixedBad = 0;
    int tried = 0;  // fixed trees measured
    int sideBySideRuns = 0;  // each setting's timed renders the price is from (retimePrice); 0: the sweep's
    // The default's pixels by how they stopped (render/Truncation.h): within
    // the tolerance (certified), by an estimated error, and those whose lost
    // light has no finite bound and that no estimate stopped; besides these,
    // bounded pixels above the tolerance at the floor or the tree budget.
    std::uint64_t pixels = 0, certified = 0, estimated = 0, unboundedNotEstimated = 0, overTolerance = 0,
                  overBudget = 0;
};

Price priceOf(const std::vector<Result>& results, std::size_t def, const std::vector<std::size_t>& tried) {
    const Result& d = results[def];
    Price p;
    p.scene = d.scene;
    p.defaultMs = d.dispatchMs.median;
    p.defaultMean = d.error.meanAbsError;
    p.defaultBad = d.error.badPixels;
    const TruncationReport& t = d.bound;
    p.pixels = t.pixels;
    p.estimated = t.estimated;
    p.overTolerance = t.overTolerance;
    p.overBudget = t.overBudget;
    // An estimated pixel is not over the tolerance; every other pixel is certified.
    p.certified = t.pixels - std::min(t.pixels, t.estimated + t.overTolerance);
    p.unboundedNotEstimated = t.unbounded - std::min(t.unbounded, t.estimated);
    p.tried = int(tried.size());
    std::optional<std::size_t> fastest, slowest;
    for (std::size_t i : tried) {
        const double ms = results[i].dispatchMs.median;
        if (asAccurate(results[i], d) && (!fastest || ms < results[*fastest].dispatchMs.median)) fastest = i;
        if (!slowest || ms > results[*slowest].dispatchMs.median) slowest = i;
    }
    const std::optional<std::size_t> setter = fastest ? fastest : slowest;
    if (!setter) return p;
    const Result& f = results[*setter];
    p.upperBound = !fastest;
    p.price = p.defaultMs / f.dispatchMs.median;
    p.fixed = f.setting.name;
    p.fixedMs = f.dispatchMs.median;
    p.fixedMean = f.error.meanAbsError;
    p.fixedBad = f.error.badPixels;
    return p;
}

// The price again from the default and the fixed tree that sets it timed side
// by side (SceneRun::measureSideBySide): chosen as the fastest of many noisy
// medians, that tree's own median is biased low (the winner's curse), and
// the sweep timed the default before the trees, minutes apart on a big scene.
constexpr int kSideBySideRuns = 5;  // a block's timed renders, at the least
void retimePrice(SceneRun& run, const std::vector<Result>& results, std::size_t def, Price& p) {
    if (std::isnan(p.price)) return;
    const auto setter = std::find_if(results.begin() + std::ptrdiff_t(def), results.end(),
                                     [&](const Result& r) { return r.setting.name == p.fixed && r.setting.front; });
    if (setter == results.end()) return;
    const double pairMs = results[def].dispatchMs.median + setter->dispatchMs.median;
    const int runs = timedRuns(kSideBySideRuns, pairMs * kSideBySideRounds, run.quick);
    const auto [defaultMs, fixedMs] = run.measureSideBySide(results[def].setting, setter->setting, runs);
    if (!(defaultMs.median > 0.0) || !(fixedMs.median > 0.0)) return;
    p.defaultMs = defaultMs.median;
    p.fixedMs = fixedMs.median;
    p.price = p.defaultMs / p.fixedMs;
    p.sideBySideRuns = runs * kSideBySideRounds;
}

std::string brief(double v) {  // three significant digits, for the log
    std::ostringstream s;
    s.precision(3);
    s << v;
    return s.str();
}

// "price of the default 1.23x (fixed min-weight 0.00391: 12.3 ms, mean 0.02/255, 3 bad); ..."
std::string describe(const Price& p) {
    std::ostringstream s;
    if (std::isnan(p.price)) {
        s << "price of the default: no fixed tree measured";
    } else {
        s << "price of the default " << (p.upperBound ? "< " : "") << brief(p.price) << "x ("
          << (p.upperBound ? "no fixed tree as accurate; slowest tried " : "") << p.fixed << ": "
          << brief(p.fixedMs) << " ms, mean " << brief(p.fixedMean) << "/255, " << p.fixedBad << " bad";
        if (p.sideBySideRuns)
            s << "; default " << brief(p.defaultMs) << " ms; timed side by side, " << p.sideBySideRuns << " runs each";
        s << ")";
    }
    s << "; default mean " << brief(p.defaultMean) << "/255, " << p.defaultBad << " bad; pixels " << p.certified
      << " certified, " << p.estimated << " estimated, " << p.unboundedNotEstimated << " unbounded not estimated";
    if (p.overBudget) s << ", " << p.overBudget << " over budget";
    s << " of " << p.pixels << "; " << p.tried << " fixed trees tried";
    return s.str();
}

// Over the scenes with a price: its geometric mean (an upper bound where
// some are) and the scene where it is largest.
struct PriceSummary {
    double geometricMean = NAN;
    int scenes = 0, upperBounds = 0;
    std::optional<Price> worst;
};

PriceSummary summarizePrices(const std::vector<Price>& prices) {
    PriceSummary s;
    double sumLog = 0.0;
    for (const Price& p : prices) {
        if (!(p.price > 0.0) || !std::isfinite(p.price)) continue;
        ++s.scenes;
        s.upperBounds += p.upperBound;
        sumLog += std::log(p.price);
        if (!s.worst || p.price > s.worst->price) s.worst = p;
    }
    if (s.scenes) s.geometricMean = std::exp(sumLog / s.scenes);
    return s;
}

std::string describe(const PriceSummary& s) {
    if (!s.worst) return "price of the default: no scene priced";
    std::ostringstream o;
    o << "price of the default: geometric mean " << (s.upperBounds ? "< " : "") << brief(s.geometricMean)
      << "x over " << s.scenes << " scenes";
    if (s.upperBounds) o << " (" << s.upperBounds << " of them upper bounds)";
    o << "; worst " << (s.worst->upperBound ? "< " : "") << brief(s.worst->price) << "x on " << s.worst->scene
      << " (" << s.worst->fixed << ")";
    return o.str();
}

// Everything the run measured, for bench.csv and bench.json.
struct Collected {
    std::vector<Result> results;
    std::vector<Price> prices;
    std::vector<Peer> peers;
    std::vector<Scaling> scaling;
    std::vector<WalkFloor> walkFloors;
    std::map<std::string, double> referenceMs, cpuDefaultMs;
};

// Peers on the shared bench scenes: depth 5, no cut-off, at the scene's own
// size (quick: the bench's): the dispatch, the whole `snell render`
// command, the CPU reference and POV-Ray.
Peer measurePeer(vk::Context& context, const BenchOptions& o, const SceneFile& file, const Scene& scene,
                 const CpuRenderer& cpu, const RenderRequest& base, int runs, std::ostream& log) {
    Peer peer;
    peer.scene = file.group + "/" + scene.name;
    peer.size = o.quick ? base.width : scene.imageSize;
    RenderRequest request = base;
    request.width = request.height = peer.size;
    request.camera = Camera::fromSpec(peer.size, scene.halfWidth);
    request.trace.maxDepth = 5;
    request.trace.minWeight = 0.0;
    request.trace.tolerance = 0.0;
    {
        ComputeRenderer renderer(context, scene, request.camera);
        renderer.render(request, false);
        std::vector<double> ms;
        for (int k = 0; k < runs; ++k) ms.push_back(renderer.render(request, false).renderMs);
        peer.snellDispatchMs = stats(ms).median;
    }
    {
        const auto start = Clock::now();
        cpu.render(request);
        peer.cpuMs = msSince(start);
    }
    const std::string output = (fs::path(o.outDir) / "peer.png").string();
    const std::string common = quote(file.path) + " --size " + std::to_string(peer.size) +
                               " --depth 5 --min-weight 0 -q -o " + quote(output);
    if (!o.snellPath.empty()) {
        const std::string cache = (fs::path(o.outDir) / "pipeline-cache").string();
        fs::remove_all(cache);
        const std::string env = "SNELL_CACHE_DIR=" + quote(cache) + " ";
        peer.coldMs = runCommand(env + quote(o.snellPath) + " render " + common);
        peer.warmMs = runCommand(env + quote(o.snellPath) + " render " + common);
        std::vector<double> ms;
        for (int k = 0; k < runs; ++k) ms.push_back(runCommand(env + quote(o.snellPath) + " render " + common));
        peer.snellCommandMs = stats(ms).median;
        fs::remove_all(cache);
    }
    fs::remove(output);
    if (std::system("command -v povray >/dev/null 2>&1") == 0) {
        const std::string pov = (fs::path(o.outDir) / (scene.name + ".pov")).string();
        std::ofstream(pov) << toPovRay(scene, 5);
        const std::string povOut = (fs::path(o.outDir) / "pov.png").string();
        const std::string command = "povray +I" + quote(pov) + " +O" + quote(povOut) + " +W" +
                                    std::to_string(peer.size) + " +H" + std::to_string(peer.size) +
                                    " -D -A +Q9 +WT2";
        std::vector<double> trace, whole;
        try {
            for (int k = 0; k < std::max(3, runs / 2); ++k) {
                std::string text;
                whole.push_back(runCommand(command, &text));
                // "Trace Time:       0 hours  0 minutes  0 seconds (0.161 seconds)"
                const std::size_t at = text.find("Trace Time:");
                const std::size_t open = at == std::string::npos ? at : text.find('(', at);
                if (open == std::string::npos) throw BenchError("POV-Ray printed no trace time");
                trace.push_back(std::atof(text.c_str() + open + 1) * 1000.0);
            }
            peer.povTraceMs = stats(trace).median;
            peer.povCommandMs = stats(whole).median;
        } catch (const BenchError& e) {
            peer.povNote = e.what();
        }
        fs::remove(povOut);
        fs::remove(pov);
    } else {
        peer.povNote = "povray is not installed (apt-get install povray)";
    }
    log << "  peers at " << peer.size << "x" << peer.size << ", depth 5: snell dispatch "
        << number(peer.snellDispatchMs) << " ms, command " << number(peer.snellCommandMs) << " ms (cold "
        << number(peer.coldMs) << ", warm " << number(peer.warmMs) << "); CPU reference " << number(peer.cpuMs)
        << " ms; POV-Ray trace "
        << (peer.povTraceMs ? number(*peer.povTraceMs) + " ms, command " + number(*peer.povCommandMs) + " ms"
                            : peer.povNote)
        << "\n";
    return peer;
}

// One scene: the exact image (the limit reference, SPEC §4;
// render/Truncation.h) and the CPU reference at the GPU's default settings
// (a peer at equal work); the named settings; the fixed trees and the price
// of the default; the peers on the shared bench scenes.
void benchScene(vk::Context& context, const BenchOptions& o, const SceneFile& file, int size, int runs,
                Collected& out, std::ostream& log) {
    const Scene scene = parseSceneFile(file.path);
    const std::string name = file.group + "/" + scene.name;
    RenderRequest base;
    base.width = base.height = size;
    base.supersample = scene.supersample;
    base.camera = Camera::fromSpec(size, scene.halfWidth);
    base.cancel = o.cancel;
    base.trace = kDefaultSettings;

    RenderRequest exactRequest = base;
    exactRequest.trace = kReferenceSettings;
    const CpuRenderer cpu(scene);
    const auto cpuStart = Clock::now();
    const Image exact = cpu.render(exactRequest);
    out.referenceMs[name] = msSince(cpuStart);
    const auto sameStart = Clock::now();
    cpu.render(base);
    out.cpuDefaultMs[name] = msSince(sameStart);

    SceneRun run{context, scene, name, file.group, base, exact, runs, o.quick, o.cancel, {}};
    const std::size_t def = out.results.size();
    const bool fp64 = context.float64Supported() && context.fp64Refusal().empty();
    for (const Setting& setting : settingsFor(scene, o.quick, fp64)) out.results.push_back(run.measure(setting));
    {
        const Result& d = out.results[def];
        log << name << ": default " << number(d.dispatchMs.median) << " ms, error " << number(d.error.meanAbsError)
            << "/255; CPU reference " << number(out.referenceMs[name]) << " ms converged, "
            << number(out.cpuDefaultMs[name]) << " ms at the default settings\n";
    }
    std::vector<std::size_t> tried;
    if (out.results[def].failure.empty()) tried = fixedSweep(run, out.results, def, o.quick);
    out.prices.push_back(priceOf(out.results, def, tried));
    retimePrice(run, out.results, def, out.prices.back());
    log << "  " << describe(out.prices.back()) << "\n";

    if (file.group == "bench") out.peers.push_back(measurePeer(context, o, file, scene, cpu, base, runs, log));

    // The walk's floor at the bench's size and, on the shared bench scenes,
    // at the peers' size.
    std::vector<int> floorSizes{size};
    if (file.group == "bench" && !o.quick && scene.imageSize != size) floorSizes.push_back(scene.imageSize);
    for (int floorSize : floorSizes) {
        RenderRequest request = base;
        request.width = request.height = floorSize;
        request.camera = Camera::fromSpec(floorSize, scene.halfWidth);
        if (const std::optional<WalkFloor> w = measureWalkFloor(context, scene, name, request, runs)) {
            log << "  " << describe(*w) << "\n";
            out.walkFloors.push_back(*w);
        }
    }
}

// Render time against sphere count at 512² (quick: 64², up to 10^4 spheres).
std::vector<Scaling> measureScaling(vk::Context& context, const BenchOptions& o, int runs, std::ostream& log) {
    std::vector<Scaling> scaling;
    const std::string generator = (fs::path(o.sourceDir) / "bench" / "make_scaling_scene.py").string();
    const int maxExponent = o.quick ? 4 : 6;
    const int scalingSize = o.quick ? 64 : 512;
    for (int e = 1; e <= maxExponent; ++e) {
        if (o.cancel && o.cancel->load()) throw BenchError("cancelled");
        Scaling s;
        s.spheres = int(std::lround(std::pow(10.0, e)));
        s.size = scalingSize;
        const std::string path = (fs::path(o.outDir) / ("scaling-" + std::to_string(s.spheres) + ".scn")).string();
        runCommand("python3 " + quote(generator) + " " + std::to_string(s.spheres) + " > " + quote(path));
        auto start = Clock::now();
        const Scene scene = parseSceneFile(path);
        s.parseMs = msSince(start);
        RenderRequest request;
        request.width = request.height = scalingSize;
        request.camera = Camera::fromSpec(scalingSize, scene.halfWidth);
        request.trace = kDefaultSettings;
        request.cancel = o.cancel;
        ComputeRenderer renderer(context, scene, request.camera);
        s.uploadMs = renderer.uploadMs();
        s.bvhBuildMs = renderer.layout().bvhBuildMs;
        s.gpuMiB = double(renderer.layout().bytes()) / (1 << 20);
        renderer.render(request, false);
        std::vector<double> ms;
        for (int k = 0; k < (e >= 5 ? 3 : runs); ++k) ms.push_back(renderer.render(request, false).renderMs);
        s.renderMs = stats(ms);
        s.peakRssMiB = peakRssMiB();
        fs::remove(path);
        log << "scaling: " << s.spheres << " spheres: parse " << number(s.parseMs) << " ms, BVH "
            << number(s.bvhBuildMs) << " ms, render " << number(s.renderMs.median) << " ms at " << scalingSize
            << "², scene on the GPU " << number(s.gpuMiB) << " MiB\n";
        scaling.push_back(s);
    }
    return scaling;
}

// bench.csv: one row per scene and setting; the price of the default (and
// the default's pixels by how they stopped) on the default's row.
void writeCsv(const fs::path& path, const Collected& c, const Ceiling& ceiling) {
    std::map<std::string, const Price*> priceOfScene;
    for (const Price& p : c.prices) priceOfScene[p.scene] = &p;
    std::ofstream csv(path);
    csv << "scene,setting,precision,bvh,depth,min_weight,supersample,size,spheres,dispatch_ms_median,"
           "dispatch_ms_min,dispatch_ms_max,timing,rays_primary,rays_shadow,rays_reflected,rays_refracted,"
           "rays_per_s,mean_abs_error,rmse,psnr,bad_fraction,max_error,non_finite,ceiling_fraction,failure,"
           "bad_pixels,front,price,price_is_upper_bound,price_setting,pixels_certified,pixels_estimated,"
           "pixels_unbounded_not_estimated\n";
    for (const Result& r : c.results) {
        const double raysPerSecond = r.dispatchMs.median > 0 ? r.rays.total() / (r.dispatchMs.median * 1e-3) : 0;
        // Ray–sphere tests a second without a BVH, against the micro-kernel.
        const double ceilingFraction =
            r.bvhUsed || r.dispatchMs.median <= 0
                ? NAN
                : (double(r.rays.total()) * r.spheres / (r.dispatchMs.median * 1e-3)) / ceiling.centreRadius;
        csv << r.scene << ",\"" << r.setting.name << "\","
            << (r.setting.precision == gpu::Precision::Fp64 ? "fp64" : "fp32") << ","
            << (r.bvhUsed ? "on" : "off") << "," << r.setting.depth << "," << r.setting.minWeight << ","
            << r.supersample << "," << r.size << "," << r.spheres << "," << number(r.dispatchMs.median) << ","
            << number(r.dispatchMs.min) << "," << number(r.dispatchMs.max) << ","
            << (r.gpuTimed ? "gpu" : "host") << "," << r.rays.primary << "," << r.rays.shadow << ","
            << r.rays.reflected << "," << r.rays.refracted << "," << number(raysPerSecond) << ","
            << number(r.error.meanAbsError) << "," << number(r.error.rmse) << "," << number(r.error.psnr) << ","
            << number(r.error.badFraction) << "," << r.error.maxError << "," << r.error.nonFinite << ","
            << (std::isnan(ceilingFraction) ? "" : number(ceilingFraction)) << ",\"" << r.failure << "\","
            << r.error.badPixels << "," << (r.setting.front ? 1 : 0) << ",";
        const auto p = priceOfScene.find(r.scene);
        if (r.setting.name == "default" && p != priceOfScene.end() && !std::isnan(p->second->price)) {
            const Price& price = *p->second;
            csv << number(price.price) << "," << (price.upperBound ? 1 : 0) << ",\"" << price.fixed << "\","
                << price.certified << "," << price.estimated << "," << price.unboundedNotEstimated << "\n";
        } else {
            csv << ",,,,,\n";
        }
    }
}

void writeResultJson(std::ostream& json, const Result& r, const Collected& c) {
    json << "    {\"scene\": " << jsonString(r.scene) << ", \"setting\": " << jsonString(r.setting.name)
         << ", \"precision\": \"" << (r.setting.precision == gpu::Precision::Fp64 ? "fp64" : "fp32")
         << "\", \"bvh\": " << (r.bvhUsed ? "true" : "false") << ", \"depth\": " << r.setting.depth
         << ", \"min_weight\": " << number(r.setting.minWeight) << ", \"supersample\": " << r.supersample
         << ", \"spheres\": " << r.spheres << ", \"dispatch_ms\": {\"median\": " << number(r.dispatchMs.median)
         << ", \"min\": " << number(r.dispatchMs.min) << ", \"max\": " << number(r.dispatchMs.max)
         << "}, \"rays\": {\"primary\": " << r.rays.primary << ", \"shadow\": " << r.rays.shadow
         << ", \"reflected\": " << r.rays.reflected << ", \"refracted\": " << r.rays.refracted
         << "}, \"error\": " << r.error.json() << ", \"tolerance\": " << number(r.setting.tolerance)
         << ", \"front\": " << (r.setting.front ? "true" : "false")
         << ", \"stated_bound\": {\"max\": " << number(255.0 * r.bound.maxBound)
         << ", \"mean\": " << number(255.0 * r.bound.meanBound()) << ", \"unbounded_pixels\": " << r.bound.unbounded
         << ", \"estimated_pixels\": " << r.bound.estimated << ", \"over_tolerance_pixels\": "
         << r.bound.overTolerance << ", \"over_budget_pixels\": " << r.bound.overBudget << "}"
         << ", \"reference_ms\": " << number(c.referenceMs.at(r.scene))
         << ", \"cpu_default_ms\": " << number(c.cpuDefaultMs.at(r.scene))
         << ", \"failure\": " << jsonString(r.failure) << "}";
}

void writePriceJson(std::ostream& json, const Price& p) {
    json << "    {\"scene\": " << jsonString(p.scene) << ", \"default_ms\": " << number(p.defaultMs)
         << ", \"default_mean_abs_error\": " << number(p.defaultMean) << ", \"default_bad_pixels\": " << p.defaultBad
         << ", \"price\": " << number(p.price) << ", \"price_is_upper_bound\": " << (p.upperBound ? "true" : "false")
         << ", \"fixed_setting\": " << (p.fixed.empty() ? "null" : jsonString(p.fixed))
         << ", \"fixed_ms\": " << number(p.fixedMs) << ", \"fixed_mean_abs_error\": " << number(p.fixedMean)
         << ", \"fixed_bad_pixels\": " << p.fixedBad << ", \"fixed_tried\": " << p.tried
         << ", \"side_by_side_runs\": " << p.sideBySideRuns
         << ", \"pixels\": {\"total\": " << p.pixels << ", \"certified\": " << p.certified
         << ", \"estimated\": " << p.estimated << ", \"unbounded_not_estimated\": " << p.unboundedNotEstimated
         << ", \"over_tolerance\": " << p.overTolerance << ", \"over_budget\": " << p.overBudget << "}}";
}

void writePriceSummaryJson(std::ostream& json, const PriceSummary& s) {
    json << "{\"geometric_mean\": " << number(s.geometricMean) << ", \"scenes\": " << s.scenes
         << ", \"upper_bounds\": " << s.upperBounds
         << ", \"worst_scene\": " << (s.worst ? jsonString(s.worst->scene) : "null")
         << ", \"worst_price\": " << (s.worst ? number(s.worst->price) : "null")
         << ", \"worst_is_upper_bound\": " << (s.worst && s.worst->upperBound ? "true" : "false")
         << ", \"worst_fixed_setting\": " << (s.worst ? jsonString(s.worst->fixed) : "null") << "}";
}

// bench.json: everything, for tools.
void writeJson(const fs::path& path, const Collected& c, const Ceiling& ceiling, vk::Context& context,
               const std::string& device, int size, int runs) {
    std::ofstream json(path);
    json << "{\n  \"device\": " << jsonString(device) << ",\n  \"driver\": " << jsonString(context.driverInfo())
         << ",\n  \"size\": " << size << ",\n  \"runs\": " << runs
         << ",\n  \"timing\": \"" << (context.timestampsSupported() ? "gpu-timestamps" : "host") << "\""
         << ",\n  \"ceiling_tests_per_s\": {\"centre_radius\": " << number(ceiling.centreRadius)
         << ", \"inverse_matrix\": " << number(ceiling.matrix) << "},\n  \"floor\": {\"size\": "
         << ceiling.floorSize << ", \"store_kernel_ms\": " << number(ceiling.storeMs)
         << ", \"empty_scene_ms\": " << number(ceiling.emptySceneMs) << "},\n  \"results\": [\n";
    for (std::size_t i = 0; i < c.results.size(); ++i) {
        writeResultJson(json, c.results[i], c);
        json << (i + 1 < c.results.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"prices\": [\n";
    for (std::size_t i = 0; i < c.prices.size(); ++i) {
        writePriceJson(json, c.prices[i]);
        json << (i + 1 < c.prices.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"price_summary\": ";
    writePriceSummaryJson(json, summarizePrices(c.prices));
    json << ",\n  \"peers\": [\n";
    for (std::size_t i = 0; i < c.peers.size(); ++i) {
        const Peer& p = c.peers[i];
        json << "    {\"scene\": " << jsonString(p.scene) << ", \"size\": " << p.size
             << ", \"snell_dispatch_ms\": " << number(p.snellDispatchMs)
             << ", \"snell_command_ms\": " << number(p.snellCommandMs) << ", \"first_image_cold_ms\": "
             << number(p.coldMs) << ", \"first_image_warm_ms\": " << number(p.warmMs)
             << ", \"cpu_reference_ms\": " << number(p.cpuMs)
             << ", \"povray_trace_ms\": " << (p.povTraceMs ? number(*p.povTraceMs) : "null")
             << ", \"povray_command_ms\": " << (p.povCommandMs ? number(*p.povCommandMs) : "null")
             << ", \"note\": " << jsonString(p.povNote) << "}" << (i + 1 < c.peers.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"walk_floors\": [\n";
    for (std::size_t i = 0; i < c.walkFloors.size(); ++i) {
        const WalkFloor& w = c.walkFloors[i];
        json << "    {\"scene\": " << jsonString(w.scene) << ", \"size\": " << w.size
             << ", \"floor_kernel_ms\": " << number(w.floorMs) << ", \"floor_kernel_rays\": " << w.floorRays
             << ", \"floor_kernel_hits\": " << w.floorHits << ", \"floor_kernel_blocked\": " << w.floorBlocked
             << ", \"render_depth0_ms\": " << number(w.renderMs) << ", \"render_depth0_rays\": " << w.renderRays
             << "}" << (i + 1 < c.walkFloors.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"scaling\": [\n";
    for (std::size_t i = 0; i < c.scaling.size(); ++i) {
        const Scaling& s = c.scaling[i];
        json << "    {\"spheres\": " << s.spheres << ", \"size\": " << s.size << ", \"parse_ms\": "
             << number(s.parseMs) << ", \"bvh_build_ms\": " << number(s.bvhBuildMs)
             << ", \"upload_ms\": " << number(s.uploadMs) << ", \"render_ms\": {\"median\": "
             << number(s.renderMs.median) << ", \"min\": " << number(s.renderMs.min) << ", \"max\": "
             << number(s.renderMs.max) << "}, \"gpu_scene_mib\": " << number(s.gpuMiB)
             << ", \"peak_rss_mib\": " << number(s.peakRssMiB) << "}" << (i + 1 < c.scaling.size() ? "," : "")
             << "\n";
    }
    json << "  ]\n}\n";
}

}  // namespace

void runBench(const BenchOptions& o, std::ostream& log) {
    const int size = o.size > 0 ? o.size : (o.quick ? 32 : 128);
    const int runs = std::max(5, o.runs);
    fs::create_directories(o.outDir);
    const std::vector<SceneFile> files = collectScenes(o);
    if (files.empty()) throw BenchError("no scenes to benchmark");

    vk::ContextOptions contextOptions;
    contextOptions.deviceIndex = o.gpu;
    vk::Context context(contextOptions);
    const std::string device = context.deviceName() + " (" + context.driverInfo() + ")";
    log << "bench: " << files.size() << " scenes at " << size << "x" << size << ", " << runs
        << " timed runs per setting, on " << device
        << (context.timestampsSupported() ? "" : "; no GPU timestamps: host timing") << "\n";

    const auto ceilingStart = Clock::now();
    const Ceiling ceiling = measureCeiling(context, runs, o.quick);
    log << "ceiling: " << ceiling.centreRadius * 1e-9 << " G ray-sphere tests/s (centre+radius), "
        << ceiling.matrix * 1e-9 << " G (inverse matrix); floor at " << ceiling.floorSize << "²: store-only kernel "
        << number(ceiling.storeMs) << " ms, empty scene " << number(ceiling.emptySceneMs) << " ms; "
        << msSince(ceilingStart) / 1000 << " s\n";

    Collected collected;
    for (const SceneFile& file : files) {
        if (o.cancel && o.cancel->load()) throw BenchError("cancelled");
        benchScene(context, o, file, size, runs, collected, log);
    }
    if (o.scaling) collected.scaling = measureScaling(context, o, runs, log);

    writeCsv(fs::path(o.outDir) / "bench.csv", collected, ceiling);
    writeJson(fs::path(o.outDir) / "bench.json", collected, ceiling, context, device, size, runs);
    log << describe(summarizePrices(collected.prices)) << "\n";
    log << "bench: wrote " << (fs::path(o.outDir) / "bench.csv").string()
        << " and bench.json; bench/summarize.py makes the tables and the plot\n";
}

}  // namespace snell
