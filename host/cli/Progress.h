// A progress bar on standard error, only when it is a terminal: the pixels
// finished, the time so far, an estimate of the time left and the rays a
// second, a few times a second; erased when the render ends.
//
// The time left: a render's cost is uneven over the image (sky above, glass
// below), and within a region the cheap pixels finish first, so
// extrapolating the pixels done misleads. Given the expected time of each
// region in the order the renderer finishes them (from a sparse render of
// the same image, expectCost), the time left is the unfinished regions'
// expected time, scaled by how the finished ones compared with theirs, less
// the time the current one has had. Without it, the pixels' pace.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace snell::cli {

class Progress {
public:
    explicit Progress(bool enabled);
    ~Progress() { done(); }
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    // The callback a RenderRequest takes (empty when the bar is off).
    std::function<void(double fraction, std::uint64_t rays)> callback();
    // Erases the bar (before any message that follows the render).
    void done();
    bool enabled() const { return enabled_; }
    // The expected seconds of each region, in order; the render starts now.
    void expectCost(std::vector<double> regions);
    // The time left after `elapsed` seconds of rendering, with `fraction`
    // (regions finished plus the current one's share, over their count)
    // done. Also notes the regions finished.
    double secondsLeft(double elapsed, double fraction);

private:
    using Clock = std::chrono::steady_clock;
    void show(double fraction, std::uint64_t rays);

    bool enabled_;
    std::vector<double> cumulativeCost_;  // expected seconds before each region, and of all
    std::size_t regionsDone_ = 0;
    double secondsWhenDone_ = 0.0;       // the render's time when the last finished region ended
    Clock::time_point renderStart_;
    bool shown_ = false;
    std::size_t width_ = 0;
    std::mutex mutex_;
    Clock::time_point start_;
    Clock::time_point last_{};
};

// "12.3 s", "4 min 05 s", "2 h 10 min".
std::string formatDuration(double seconds);

}  // namespace snell::cli
