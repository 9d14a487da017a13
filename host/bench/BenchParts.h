// The parts of `snell bench` (Bench.h) and what they share: the settings,
// results and measurements, and each part's entry points.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "bench/Bench.h"
#include "gpu/ComputeRenderer.h"
#include "metrics/ImageMetrics.h"
#include "reference/CpuRenderer.h"
#include "render/RenderRequest.h"
#include "render/Truncation.h"
#include "scene/Scene.h"
#include "vulkan/VulkanContext.h"

namespace snell::bench {

namespace fs = std::filesystem;

struct Stats {
    double median = 0.0, min = 0.0, max = 0.0;
};
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

// A CPU render's time, taken as the GPU's are: the median of several renders
// after an untimed one (threads, caches and the scene's traps warmed), or
// that one alone where it took kCpuSingleRunMs or more. A render of a
// millisecond on its threads takes ten when the scheduler keeps one waiting
// on a busy machine: at least `runs`, as many as fill kCpuBudgetMs.
struct CpuTiming {
    Stats ms;
    int runs = 0;
};
constexpr double kCpuSingleRunMs = 500.0, kCpuBudgetMs = 200.0;
constexpr int kCpuMaxRuns = 101;

// POV-Ray's image against snell's at the same tree (PovExport.h), in 1/255:
// compared only where the two models agree (povModelAgrees), else `note` says why not.
struct PovAgreement {
    bool compared = false;
    ImageMetrics metrics;     // POV-Ray's image against snell's (the GPU's, fp32)
    ImageMetrics cpuMetrics;  // against the CPU reference's at the same tree (double precision)
    bool agrees = false;      // metrics within `snell compare`'s defaults: mean 0.5/255, 0.1 % of pixels over 3/255
    std::string note;
};

// The peers on one shared bench scene, all tracing the same tree: snell's
// depth kPeerDepth without a cut-off, one ray a pixel, POV-Ray's
// max_trace_level one more (it counts the camera ray).
constexpr int kPeerDepth = 5;
struct Peer {
    std::string scene;
    int size = 0;
    double snellDispatchMs = 0.0, snellCommandMs = 0.0, coldMs = NAN, warmMs = 0.0;  // cold: NaN in a quick run
    CpuTiming cpu;
    std::optional<double> povTraceMs, povCommandMs;
    double povTraceResolutionMs = 0.0;  // POV-Ray prints its trace time to this step
    std::string povNote;
    PovAgreement agreement;
};

struct Scaling {
    int spheres = 0;
    double parseMs = 0.0, bvhBuildMs = 0.0, uploadMs = 0.0;
    Stats renderMs;
    double gpuMiB = 0.0, peakRssMiB = 0.0;
    int size = 0;
};
// The device's ceiling: ray–sphere tests per second of the micro-kernel; and
// its floor: a dispatch that only stores a pixel per invocation, against the
// renderer on a scene with nothing in it, at the same size.
struct Ceiling {
    double centreRadius = 0.0, matrix = 0.0;  // tests per second
    int floorSize = 0;                         // pixels a side
    double storeMs = 0.0, emptySceneMs = 0.0;  // median dispatch times
};

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

struct SceneFile {
    std::string path, group;
};
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
    static constexpr int kSideBySideRounds = 3;
    std::pair<Stats, Stats> measureSideBySide(const Setting& a, const Setting& b, int runs);

    RenderRequest requestFor(const Setting& setting) const;
    ComputeRenderer& rendererFor(const Setting& setting);
};
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
// Over the scenes with a price: its geometric mean (an upper bound where
// some are) and the scene where it is largest.
struct PriceSummary {
    double geometricMean = NAN;
    int scenes = 0, upperBounds = 0;
    std::optional<Price> worst;
};
// Everything the run measured, for bench.csv and bench.json.
struct Collected {
    std::vector<Result> results;
    std::vector<Price> prices;
    std::vector<Peer> peers;
    std::vector<Scaling> scaling;
    std::vector<WalkFloor> walkFloors;
    std::map<std::string, CpuTiming> referenceMs, cpuDefaultMs;
};

// Statistics and subprocesses (BenchStatistics.cpp)
Stats stats(std::vector<double> v);
std::string number(double v);
CpuTiming timeCpu(const std::function<void()>& render, double firstMs, int runs);
// Two renders timed in turn (a, b, a, b, ...), so that the machine's drift moves both alike.
std::pair<CpuTiming, CpuTiming> timeCpuSideBySide(const std::function<void()>& a, double firstA,
                                                  const std::function<void()>& b, double firstB, int runs);
std::string describe(const CpuTiming& t);  // "0.31 ms (median of 5)"
// a / b where a is known only to ±halfStep (a time printed to a step): to
// three digits, or two, where the step allows them, else the range it leaves
// ("2.6-3.6x"; "below 4.1x" where a may be 0).
std::string ratioText(double a, double halfStep, double b);
double peakRssMiB();
double runCommand(const std::string& command, std::string* output = nullptr);
std::string quote(const std::string& s);

// The device's floors: the ray–sphere ceiling, the store-only floor and the BVH walk's floor (DeviceFloors.cpp)
Ceiling measureCeiling(vk::Context& context, int runs, bool quick);
std::optional<WalkFloor> measureWalkFloor(vk::Context& context, const Scene& scene, const std::string& name,
                                          const RenderRequest& base, int runs);
std::string describe(const WalkFloor& w);

// The sweep: each scene's settings and the fixed trees the default is priced against (Sweep.cpp)
std::vector<Setting> settingsFor(const Scene& scene, bool quick, bool fp64);
int timedRuns(int runs, double warmUpMs, bool quick);
bool asAccurate(const Result& r, const Result& def);
std::vector<std::size_t> fixedSweep(SceneRun& run, std::vector<Result>& results, std::size_t def, bool quick);

// Pricing the default (Pricing.cpp)
std::string describe(const Price& p);
std::string describe(const PriceSummary& s);
Price priceOf(const std::vector<Result>& results, std::size_t def, const std::vector<std::size_t>& tried);
void retimePrice(SceneRun& run, const std::vector<Result>& results, std::size_t def, Price& p);
PriceSummary summarizePrices(const std::vector<Price>& prices);

// Peers: the CPU reference and POV-Ray on the shared bench scenes (Peers.cpp)
Peer measurePeer(vk::Context& context, const BenchOptions& o, const SceneFile& file, const Scene& scene,
                 const CpuRenderer& cpu, const RenderRequest& base, int runs, std::ostream& log);
// "mean 0.01/255, max 2/255, 0 pixels (0.00 %) over 3/255: agrees", or why not compared
std::string describe(const PovAgreement& a);

// The end of a run: the summary table, bench.md and bench.png (Summary.cpp)
void printSummary(const Collected& c, int size, bool gpuTimed, std::ostream& out);
void writeTablesAndPlot(const BenchOptions& o, std::ostream& log);

// The report: bench.csv and bench.json (Report.cpp)
void writeCsv(const fs::path& path, const Collected& c, const Ceiling& ceiling);
void writeJson(const fs::path& path, const Collected& c, const Ceiling& ceiling, vk::Context& context,
               const std::string& device, int size, int runs);

}  // namespace snell::bench
