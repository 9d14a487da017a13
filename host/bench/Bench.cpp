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

#include "bench/PovExport.h"
#include "common/Json.h"
#include "gpu/ComputeRenderer.h"
#include "kernel_layout.h"
#include "metrics/ImageMetrics.h"
#include "ray_sphere_kernel_comp_spv.h"
#include "ray_sphere_kernel_matrix_comp_spv.h"
#include "store_kernel_comp_spv.h"
#include "reference/CpuRenderer.h"
#include "scene/Parser.h"
#include "scene/Transform.h"
#include "vulkan/ComputeKernel.h"
#include "vulkan/VulkanContext.h"

namespace snell {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

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
    vk::Buffer output = context.createBuffer(rays * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
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
    vk::Buffer image = context.createBuffer(VkDeviceSize(pixels) * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
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


std::vector<Setting> settingsFor(const Scene& scene, bool quick) {
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
    Setting fp64{"fp64"};
    fp64.precision = gpu::Precision::Fp64;
    s.push_back(fp64);
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

}  // namespace

void runBench(const BenchOptions& o, std::ostream& log) {
    const int size = o.size > 0 ? o.size : (o.quick ? 48 : 128);
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

    auto cancelled = [&] { return o.cancel && o.cancel->load(); };
    std::vector<Result> results;
    std::vector<Peer> peers;
    std::map<std::string, double> referenceMs, cpuDefaultMs;
    for (const SceneFile& file : files) {
        if (cancelled()) throw BenchError("cancelled");
        const Scene scene = parseSceneFile(file.path);
        const std::string name = file.group + "/" + scene.name;
        RenderRequest base;
        base.width = base.height = size;
        base.supersample = scene.supersample;
        base.camera = Camera::fromSpec(size, scene.halfWidth);
        base.cancel = o.cancel;
        base.trace = kDefaultSettings;

        // The exact image: the limit reference (SPEC §4; render/Truncation.h).
        RenderRequest exactRequest = base;
        exactRequest.trace = kReferenceSettings;
        const CpuRenderer cpu(scene);
        const auto cpuStart = Clock::now();
        const Image exact = cpu.render(exactRequest);
        referenceMs[name] = msSince(cpuStart);
        // The CPU reference again, at the GPU's default settings: a peer at equal work.
        RenderRequest sameRequest = base;
        sameRequest.trace = kDefaultSettings;
        const auto sameStart = Clock::now();
        cpu.render(sameRequest);
        cpuDefaultMs[name] = msSince(sameStart);

        std::map<std::pair<int, int>, std::unique_ptr<ComputeRenderer>> renderers;
        const std::vector<Setting> settings = settingsFor(scene, o.quick);
        for (const Setting& setting : settings) {
            Result r;
            r.scene = name;
            r.group = file.group;
            r.setting = setting;
            r.size = size;
            r.spheres = int(scene.spheres.size());
            RenderRequest request = base;
            request.trace.maxDepth = setting.depth;
            request.trace.minWeight = setting.minWeight;
            request.trace.tolerance = setting.tolerance;
            request.truncation = &r.bound;
            if (setting.supersample) request.supersample = setting.supersample;
            r.supersample = request.supersample;
            try {
                auto& renderer = renderers[{int(setting.precision), int(setting.bvh)}];
                if (!renderer)
                    renderer = std::make_unique<ComputeRenderer>(context, scene, base.camera, setting.precision,
                                                                 setting.bvh);
                r.bvhUsed = renderer->layout().usesBvh();
                renderer->render(request, false);  // warm-up: pipeline and first dispatch
                std::vector<double> ms;
                Image image;
                for (int k = 0; k < runs; ++k) {
                    GpuRenderResult g = renderer->render(request, false);
                    ms.push_back(g.renderMs);
                    r.gpuTimed = g.gpuTimed;
                    if (k == 0) image = std::move(g.image);
                }
                r.dispatchMs = stats(ms);
                r.rays = renderer->render(request, true).rays;
                r.error = compareImages(image, exact);
            } catch (const vk::VulkanError& e) {
                if (cancelled()) throw;
                r.failure = e.what();
            }
            results.push_back(r);
        }
        const Result& def = results[results.size() - settings.size()];
        log << name << ": default " << number(def.dispatchMs.median) << " ms, error "
            << number(def.error.meanAbsError) << "/255; CPU reference " << number(referenceMs[name])
            << " ms converged, " << number(cpuDefaultMs[name]) << " ms at the default settings\n";

        // Peers on the shared bench scenes: depth 5, no cut-off, at the scene's own size.
        if (file.group != "bench") continue;
        Peer peer;
        peer.scene = name;
        peer.size = o.quick ? size : scene.imageSize;
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
        peers.push_back(peer);
    }

    // Scaling: render time against sphere count at 512² (quick: 64²).
    std::vector<Scaling> scaling;
    const std::string generator = (fs::path(o.sourceDir) / "bench" / "make_scaling_scene.py").string();
    const int maxExponent = o.quick ? 4 : 6;
    const int scalingSize = o.quick ? 64 : 512;
    for (int e = 1; e <= maxExponent; ++e) {
        if (cancelled()) throw BenchError("cancelled");
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

    // CSV: one row per scene and setting.
    {
        std::ofstream csv(fs::path(o.outDir) / "bench.csv");
        csv << "scene,setting,precision,bvh,depth,min_weight,supersample,size,spheres,dispatch_ms_median,"
               "dispatch_ms_min,dispatch_ms_max,timing,rays_primary,rays_shadow,rays_reflected,rays_refracted,"
               "rays_per_s,mean_abs_error,rmse,psnr,bad_fraction,max_error,non_finite,ceiling_fraction,failure\n";
        for (const Result& r : results) {
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
                << (std::isnan(ceilingFraction) ? "" : number(ceilingFraction)) << ",\"" << r.failure << "\"\n";
        }
    }
    // JSON: everything, for tools.
    {
        std::ofstream json(fs::path(o.outDir) / "bench.json");
        json << "{\n  \"device\": " << jsonString(device) << ",\n  \"driver\": " << jsonString(context.driverInfo())
             << ",\n  \"size\": " << size << ",\n  \"runs\": " << runs
             << ",\n  \"timing\": \"" << (context.timestampsSupported() ? "gpu-timestamps" : "host") << "\""
             << ",\n  \"ceiling_tests_per_s\": {\"centre_radius\": " << number(ceiling.centreRadius)
             << ", \"inverse_matrix\": " << number(ceiling.matrix) << "},\n  \"floor\": {\"size\": "
             << ceiling.floorSize << ", \"store_kernel_ms\": " << number(ceiling.storeMs)
             << ", \"empty_scene_ms\": " << number(ceiling.emptySceneMs) << "},\n  \"results\": [\n";
        for (std::size_t i = 0; i < results.size(); ++i) {
            const Result& r = results[i];
            json << "    {\"scene\": " << jsonString(r.scene) << ", \"setting\": " << jsonString(r.setting.name)
                 << ", \"precision\": \"" << (r.setting.precision == gpu::Precision::Fp64 ? "fp64" : "fp32")
                 << "\", \"bvh\": " << (r.bvhUsed ? "true" : "false") << ", \"depth\": " << r.setting.depth
                 << ", \"min_weight\": " << number(r.setting.minWeight) << ", \"supersample\": " << r.supersample
                 << ", \"spheres\": " << r.spheres << ", \"dispatch_ms\": {\"median\": " << number(r.dispatchMs.median)
                 << ", \"min\": " << number(r.dispatchMs.min) << ", \"max\": " << number(r.dispatchMs.max)
                 << "}, \"rays\": {\"primary\": " << r.rays.primary << ", \"shadow\": " << r.rays.shadow
                 << ", \"reflected\": " << r.rays.reflected << ", \"refracted\": " << r.rays.refracted
                 << "}, \"error\": " << r.error.json() << ", \"tolerance\": " << number(r.setting.tolerance)
                 << ", \"stated_bound\": {\"max\": " << number(255.0 * r.bound.maxBound)
                 << ", \"mean\": " << number(255.0 * r.bound.meanBound())
                 << ", \"unbounded_pixels\": " << r.bound.unbounded << "}"
                 << ", \"reference_ms\": " << number(referenceMs[r.scene])
                 << ", \"cpu_default_ms\": " << number(cpuDefaultMs[r.scene])
                 << ", \"failure\": " << jsonString(r.failure) << "}" << (i + 1 < results.size() ? "," : "") << "\n";
        }
        json << "  ],\n  \"peers\": [\n";
        for (std::size_t i = 0; i < peers.size(); ++i) {
            const Peer& p = peers[i];
            json << "    {\"scene\": " << jsonString(p.scene) << ", \"size\": " << p.size
                 << ", \"snell_dispatch_ms\": " << number(p.snellDispatchMs)
                 << ", \"snell_command_ms\": " << number(p.snellCommandMs) << ", \"first_image_cold_ms\": "
                 << number(p.coldMs) << ", \"first_image_warm_ms\": " << number(p.warmMs)
                 << ", \"cpu_reference_ms\": " << number(p.cpuMs)
                 << ", \"povray_trace_ms\": " << (p.povTraceMs ? number(*p.povTraceMs) : "null")
                 << ", \"povray_command_ms\": " << (p.povCommandMs ? number(*p.povCommandMs) : "null")
                 << ", \"note\": " << jsonString(p.povNote) << "}" << (i + 1 < peers.size() ? "," : "") << "\n";
        }
        json << "  ],\n  \"scaling\": [\n";
        for (std::size_t i = 0; i < scaling.size(); ++i) {
            const Scaling& s = scaling[i];
            json << "    {\"spheres\": " << s.spheres << ", \"size\": " << s.size << ", \"parse_ms\": "
                 << number(s.parseMs) << ", \"bvh_build_ms\": " << number(s.bvhBuildMs)
                 << ", \"upload_ms\": " << number(s.uploadMs) << ", \"render_ms\": {\"median\": "
                 << number(s.renderMs.median) << ", \"min\": " << number(s.renderMs.min) << ", \"max\": "
                 << number(s.renderMs.max) << "}, \"gpu_scene_mib\": " << number(s.gpuMiB)
                 << ", \"peak_rss_mib\": " << number(s.peakRssMiB) << "}" << (i + 1 < scaling.size() ? "," : "")
                 << "\n";
        }
        json << "  ]\n}\n";
    }
    log << "bench: wrote " << (fs::path(o.outDir) / "bench.csv").string()
        << " and bench.json; bench/summarize.py makes the tables and the plot\n";
}

}  // namespace snell
