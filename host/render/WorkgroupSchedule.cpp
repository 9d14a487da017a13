#include "render/WorkgroupSchedule.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <queue>

namespace snell {

double scheduleSecondsLeft(const std::vector<WorkgroupWork>& workgroups, std::size_t executors) {
    double done = 0.0, seconds = 0.0;
    for (const WorkgroupWork& w : workgroups)
        if (w.secondsRunning > 0.0) {
            done += w.done;
            seconds += w.secondsRunning;
        }
    if (!(done > 0.0) || !(seconds > 0.0)) return -1.0;
    const double pace = seconds / done;  // seconds a unit of cost, on one executor
    // When each executor comes free: first the running workgroups, then the
    // rest in order, each on the executor that frees first (list scheduling).
    std::priority_queue<double, std::vector<double>, std::greater<double>> freeAt;
    for (const WorkgroupWork& w : workgroups)
        if (w.secondsRunning > 0.0 && w.done < w.total) freeAt.push(pace * (w.total - w.done));
    while (freeAt.size() < std::max<std::size_t>(executors, 1)) freeAt.push(0.0);
    double end = 0.0;
    for (const WorkgroupWork& w : workgroups) {
        if (w.secondsRunning > 0.0 || !(w.total > w.done)) continue;
        const double start = freeAt.top();
        freeAt.pop();
        freeAt.push(start + pace * (w.total - w.done));
    }
    while (!freeAt.empty()) {
        end = std::max(end, freeAt.top());
        freeAt.pop();
    }
    return end;
}

std::uint32_t spreadingStride(std::uint32_t count) {
    const auto near = std::uint32_t(std::lround(double(count) / 1.6180339887498949));
    for (std::uint32_t d = 0; d <= count; ++d)
        for (const std::uint32_t k : {near + d, near - d})
            if (k >= 1 && k <= count && std::gcd(k, count) == 1) return k;
    return 1;
}

}  // namespace snell
