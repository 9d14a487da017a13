#include "gpu/ProgressForecast.h"

#include <algorithm>
#include <chrono>

#include "render/WorkgroupSchedule.h"

namespace snell::gpu {

// The tile's expected cost in the order its pixels are taken: the tile is
// dealt in shares of runs of a workgroup's size, run r to share r mod W, and
// each workgroup takes its share's runs in order (schedule/pixels.glsl, takePixel), so
// what a workgroup has finished is, but for the pixels in progress, the
// start of its share.
void expectTileCost(const RenderRequest& request, const TilePlan& plan, const TileParams& tile,
                    RenderProgress& progress) {
    progress.costBefore.clear();
    progress.tileCost = 0.0;
    progress.tileStart = Clock::now();
    progress.lastReport = 0.0;
    if (!request.expectedCost || request.expectedCost->empty()) return;
    const CostMap& map = *request.expectedCost;
    const std::uint64_t run = SNELL_WORKGROUP_SIZE, workgroups = plan.workgroups();
    const std::uint64_t pixels = std::uint64_t(tile.width) * tile.height, runs = (pixels + run - 1) / run;
    progress.costBefore.assign(workgroups, std::vector<double>(1, 0.0));
    progress.sharePixels.assign(workgroups, 0);
    for (std::uint64_t r = 0; r < runs; ++r) {
        double cost = 0.0;
        for (std::uint64_t k = r * run; k < std::min(pixels, (r + 1) * run); ++k)
            cost += map.at(imageColumn(tile, std::uint32_t(k % tile.width)),
                           imageRow(tile, std::uint32_t(k / tile.width)));
        std::vector<double>& before = progress.costBefore[r % workgroups];
        before.push_back(before.back() + cost);
        progress.sharePixels[r % workgroups] += std::min(run, pixels - r * run);
        progress.tileCost += cost;
    }
    progress.startedAt.assign(workgroups, -1.0);
    progress.finishedAt.assign(workgroups, -1.0);
}

namespace {

// The expected cost of a share's first `count` pixels (the order it is taken in).
double costOfFirst(const RenderProgress& progress, std::uint64_t workgroups, std::uint64_t pixels,
                   std::uint64_t share, std::uint64_t count) {
    const std::uint64_t run = SNELL_WORKGROUP_SIZE;
    const std::vector<double>& before = progress.costBefore[share];
    const std::size_t runsDone = std::min<std::size_t>(count / run, before.size() - 1);
    double done = before[runsDone];
    if (runsDone + 1 < before.size()) {
        const std::uint64_t first = (runsDone * workgroups + share) * run;  // that run's first pixel
        done += double(count % run) / double(std::min(run, pixels - first)) * (before[runsDone + 1] - before[runsDone]);
    }
    return std::min(done, before.back());
}

// Where workgroups help with each other's shares, every workgroup works on
// while any share has pixels left, so the tile's time goes with its cost:
// the cost of the pixels taken (each share's counter), less those still in
// flight at the average cost. Negative before any is taken.
double shareOfCostTaken(const std::uint32_t* counters, const RenderProgress& progress, std::uint64_t workgroups,
                        std::uint64_t pixels, std::uint64_t finished) {
    double costTaken = 0.0;
    std::uint64_t taken = 0;
    for (std::uint64_t s = 0; s < workgroups; ++s) {
        const std::uint64_t t =
            std::min<std::uint64_t>(counters[SNELL_COUNTER_COUNT + s * SNELL_COUNTER_STRIDE], progress.sharePixels[s]);
        costTaken += costOfFirst(progress, workgroups, pixels, s, t);
        taken += t;
    }
    if (taken == 0) return -1.0;
    return std::min(0.999, costTaken * std::min(1.0, double(finished) / double(taken)) / progress.tileCost);
}

}  // namespace

// The share is of the tile's pixels finished, or with an expected cost, of
// its time: where workgroups help with each other's shares, the cost done;
// else the time so far against that and the time its workgroups have left
// (WorkgroupSchedule), once they have shown their pace.
void reportProgress(const SlotState* states, const std::uint32_t* counters, const RenderRequest& request,
                    const TilePlan& plan, const TileParams& tile, RenderProgress& progress, bool tileDone) {
    const std::uint64_t run = SNELL_WORKGROUP_SIZE, workgroups = plan.workgroups();
    const std::uint64_t pixels = std::uint64_t(tile.width) * tile.height;
    const double now = std::chrono::duration<double>(Clock::now() - progress.tileStart).count();
    const double seenAt = 0.5 * (progress.lastReport + now);  // between the last report and this one
    std::uint64_t finished = 0, rays = progress.raysBefore;
    double costDone = 0.0;
    std::size_t runningNow = 0;
    std::vector<WorkgroupWork> work(progress.tileCost > 0.0 && !plan.helps ? workgroups : 0);
    for (std::uint64_t w = 0; w < workgroups; ++w) {
        std::uint64_t ofWorkgroup = 0;
        for (std::uint64_t k = w * run; k < (w + 1) * run; ++k) {
            ofWorkgroup += states[k].finished;
            rays += states[k].rays;
        }
        finished += ofWorkgroup;
        if (work.empty()) continue;
        // Its finished pixels are (but for those in progress) its share's first runs'.
        const std::uint64_t share = plan.shareOf(w);
        WorkgroupWork& wg = work[w];
        wg.done = costOfFirst(progress, workgroups, pixels, share, ofWorkgroup);
        wg.total = progress.costBefore[share].back();
        costDone += wg.done;
        if (wg.done > 0.0 && progress.startedAt[w] < 0.0) progress.startedAt[w] = seenAt;
        if (wg.done >= wg.total && progress.finishedAt[w] < 0.0) progress.finishedAt[w] = seenAt;
        if (progress.startedAt[w] >= 0.0) {
            const bool over = progress.finishedAt[w] >= 0.0;
            wg.secondsRunning = std::max((over ? progress.finishedAt[w] : now) - progress.startedAt[w], 1e-6);
            if (!over) ++runningNow;
        }
    }
    progress.lastReport = now;
    progress.running = std::max(progress.running, runningNow);
    double share = double(finished) / double(pixels);
    if (plan.helps && progress.tileCost > 0.0 && finished < pixels) {
        const double byCost = shareOfCostTaken(counters, progress, workgroups, pixels, finished);
        if (byCost >= 0.0) share = byCost;
    } else if (!work.empty() && finished < pixels) {
        const double left = scheduleSecondsLeft(work, progress.running);
        share = left >= 0.0 && now > 0.0 ? now / (now + left) : costDone / progress.tileCost;
        share = std::min(share, 0.999);
    }
    if (request.progress) request.progress((progress.tilesDone + share) / plan.count(), rays);
    if (tileDone) progress.raysBefore = rays;
}

}  // namespace snell::gpu
