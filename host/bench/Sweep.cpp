// The sweep: each scene's named settings, and the fixed trees the default is priced against.
#include "bench/BenchParts.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/Clock.h"

namespace snell::bench {

// A quick run (CI, a first look) sweeps the default and a tolerance of
// 2/255, which share its kernels (the fixed sweep adds cut-offs and depth
// caps); the other settings, fp64 and the other BVH mode each need kernels
// of their own, seconds each to compile on lavapipe.
std::vector<Setting> settingsFor(const Scene& scene, bool quick, bool fp64) {
    std::vector<Setting> s;
    s.push_back({"default"});
    // The tolerance on each pixel's stated bound (the default is 0.5/255).
    for (double t : quick ? std::vector<double>{2.0} : std::vector<double>{8.0, 2.0, 0.1}) {
        std::ostringstream name;
        name << "tolerance " << t << "/255";
        Setting x{name.str()};
        x.tolerance = t / 255.0;
        s.push_back(x);
    }
    if (scene.supersample > 1) {
        Setting one{"spp 1"};
        one.supersample = 1;
        s.push_back(one);
    }
    if (quick) return s;
    // Depth alone (no cut-off): at most 2^depth rays a pixel, so it stays small.
    for (int d : {1, 2, 3, 5, 8}) {
        Setting x{"depth " + std::to_string(d)};
        x.depth = d;
        x.minWeight = 0.0;
        x.tolerance = 0.0;
        s.push_back(x);
    }
    // The cut-off at full depth (0 is left out: a glass scene's tree then has 2^64 rays).
    for (double w : {1e-2, 1e-3, 1e-5, 1e-7}) {
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
    return s;
}


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

// A quick run's few share their kernels: a cut-off 4^-k and the depth cap k
// often need the same ray stack (gpu/KernelPolicy.cpp, rayStackEntries).
constexpr int kLastCutOff = 12, kLastCutOffQuick = 2;  // cut-offs 4^-1 .. 4^-k
constexpr int kLastDepth = 16, kLastDepthQuick = 2;     // depth caps 1 .. d

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
// (quick: 1..2), and (b) depth caps d = 1..16 (quick: 1..2) without a
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

}  // namespace snell::bench
