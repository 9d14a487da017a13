#include "render/WorkgroupSchedule.h"

#include <algorithm>
#include <functional>
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

}  // namespace snell
