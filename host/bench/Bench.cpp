#include "bench/Bench.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

#include "bench/BenchParts.h"
#include "common/Clock.h"
#include "gpu/GpuScene.h"
#include "reference/CpuRenderer.h"
#include "scene/Parser.h"

namespace snell {

using namespace bench;

namespace {

// A scene's group, named by its folder: the bench scenes (which have peers)
// and the course's by their shared names. Two scenes of one name in two
// folders (bench/glass, scenes/glass) stay two rows.
std::string groupOf(const fs::path& dir) {
    fs::path folder = dir.lexically_normal();
    if (folder.filename().empty()) folder = folder.parent_path();  // "scenes/"
    const std::string name = folder.filename().string();
    return name == "bench-scenes" ? "bench" : name == "course-scenes" ? "course" : name.empty() ? "given" : name;
}

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
            if (fs::is_directory(s)) addDir(s, groupOf(s));
            else out.push_back({s, groupOf(fs::absolute(s).parent_path())});
        }
        return out;
    }
    if (o.quick) {
        // Two scenes that take every part of the bench: glass (refraction,
        // estimated pixels) and a BVH of opaque spheres (the walk's floor,
        // POV-Ray's image compared), with their peers where the shared
        // bench scenes are.
        const fs::path bench = fs::path(o.sharedDir) / "bench-scenes";
        if (fs::exists(bench / "simple.scn") && fs::exists(bench / "grid.scn"))
            return {{(bench / "simple.scn").string(), "bench"}, {(bench / "grid.scn").string(), "bench"}};
        const fs::path scenes = fs::path(o.sourceDir) / "scenes";
        return {{(scenes / "glass.scn").string(), "scenes"}, {(scenes / "grid.scn").string(), "scenes"}};
    }
    addDir(fs::path(o.sourceDir) / "scenes", "scenes");
    addDir(fs::path(o.sourceDir) / "scenes" / "hard", "hard");
    addDir(fs::path(o.sharedDir) / "course-scenes", "course");
    addDir(fs::path(o.sharedDir) / "bench-scenes", "bench");
    return out;
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
    const double exactMs = msSince(cpuStart);
    const auto sameStart = Clock::now();
    cpu.render(base);
    std::tie(out.referenceMs[name], out.cpuDefaultMs[name]) = timeCpuSideBySide(
        [&] { cpu.render(exactRequest); }, exactMs, [&] { cpu.render(base); }, msSince(sameStart), runs);

    SceneRun run{context, scene, name, file.group, base, exact, runs, o.quick, o.cancel, {}};
    const std::size_t def = out.results.size();
    const bool fp64 = context.float64Supported() && context.fp64Refusal().empty();
    for (const Setting& setting : settingsFor(scene, o.quick, fp64)) out.results.push_back(run.measure(setting));
    {
        const Result& d = out.results[def];
        log << name << ": default " << number(d.dispatchMs.median) << " ms, error " << number(d.error.meanAbsError)
            << "/255; CPU reference " << describe(out.referenceMs[name]) << " converged, "
            << describe(out.cpuDefaultMs[name]) << " at the default settings\n";
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

// Render time against sphere count at 512², 10 to 10^6 spheres (quick: 64²,
// 10 and 10^3: each count compiles a kernel).
std::vector<Scaling> measureScaling(vk::Context& context, const BenchOptions& o, int runs, std::ostream& log) {
    std::vector<Scaling> scaling;
    const std::string generator = (fs::path(o.sourceDir) / "bench" / "make_scaling_scene.py").string();
    const int maxExponent = o.quick ? 3 : 6;
    const int scalingSize = o.quick ? 64 : 512;
    for (int e = 1; e <= maxExponent; e += o.quick ? 2 : 1) {
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

}  // namespace

void runBench(const BenchOptions& o, std::ostream& log, std::ostream& summary) {
    const int size = o.size > 0 ? o.size : (o.quick ? 32 : 128);
    const int runs = std::max(5, o.runs);
    fs::create_directories(o.outDir);
    const std::vector<SceneFile> files = collectScenes(o);
    if (files.empty()) throw BenchError("no scenes to benchmark");
    const auto isBench = [](const SceneFile& f) { return f.group == "bench"; };
    if (o.scenes.empty() && std::none_of(files.begin(), files.end(), isBench))
        log << "bench: no peers: the shared bench scenes are not in "
            << (fs::path(o.sharedDir) / "bench-scenes").string() << " (--shared-dir)\n";

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
    log << "bench: wrote " << (fs::path(o.outDir) / "bench.csv").string() << " and bench.json\n";
    writeTablesAndPlot(o, log);
    log.flush();
    printSummary(collected, size, context.timestampsSupported(), summary);
}

}  // namespace snell
