// How the workgroups of a tile run, for the compute renderer: which share of
// the tile each takes, and how long a tile in progress has left. The
// compute renderer deals each workgroup its own pixels
// (shaders/schedule/pixels.glsl, takePixel), and a device runs a few
// workgroups at once, each to its end: lavapipe one a thread, in order. So the tile ends when its last workgroup
// does, and near its end fewer workgroups than executors are left and the
// tile slows: a tail that neither the pixels finished nor the cost done
// foresees, and the forecast below does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace snell {

// One workgroup's work in a tile, in the expected cost of its pixels
// (RenderRequest::expectedCost): what it has finished of its total, and for
// how many seconds it has been running (0: not started).
struct WorkgroupWork {
    double done = 0.0;
    double total = 0.0;
    double secondsRunning = 0.0;
};

// The seconds until the last workgroup ends: those running go on, those not
// started start in order as executors come free, `executors` at a time, each
// at the pace the running and finished ones have shown (their cost done over
// their seconds running). Negative where no workgroup has shown a pace yet.
double scheduleSecondsLeft(const std::vector<WorkgroupWork>& workgroups, std::size_t executors);

// lavapipe gives each thread a contiguous range of workgroup IDs, so the
// shares of the tile that neighbouring workgroups take should lie apart:
// workgroup g takes share g · stride mod count (schedule/pixels.glsl, takePixel). The
// stride nearest count / golden ratio that is coprime with count makes that
// a permutation in which any range of workgroups takes shares spread over
// the whole tile.
std::uint32_t spreadingStride(std::uint32_t count);

}  // namespace snell
