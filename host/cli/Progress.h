// A progress bar on standard error, only when it is a terminal: the pixels
// finished, the time so far, an estimate of the time left and the rays a
// second of the render (not of the kernel's compile or the estimate's probe
// before it), a few times a second; erased when the render ends. Before
// the render, the same line says what is going on (during()).
//
// The time left: a render's cost is uneven over the image (sky above, glass
// below), and within a region the cheap pixels finish first, so
// extrapolating the pixels done misleads. A sparse render of the same image
// gives each region (in the order the renderer finishes them) two expected
// costs, its time and its rays (expectCost). Neither is right everywhere: the
// probe's time is right where cost is spread (a SphereFlake), but a small
// region with a rare expensive pixel runs as long as that pixel alone and is
// overstated; its rays miss that rays cost more deep in a BVH than in the
// sky. The bar uses the one that has predicted the finished regions better:
// the unfinished regions' cost at the pace the finished ones took it. The
// current region is that expectation, less the time it has had, weighed
// against its own pace over its progress (its rays so far against those plus
// the expected rays of its unfinished pixels, or where the renderer reports
// it, the share of its time done by the renderer's own forecast), which
// counts for more as the region goes on; that progress also counts in the
// pace of the rest. Without an expectation, the pixels' pace.
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
    // Runs `work`, saying "snell: WHAT... 1.2 s" on the bar's line while it
    // runs, once it has run for a quarter of a second (a kernel taken from
    // a cache takes milliseconds: nothing flickers).
    void during(const std::string& what, const std::function<void()>& work);
    // The render starts now: the rays a second count from here.
    void renderStarts();
    bool enabled() const { return enabled_; }
    // Each region's expected seconds and rays, in order; the render starts now.
    // `sharesOfTime`: the renderer reports the region in progress by the
    // share of its time done (RenderRequest::expectedCost), not of its pixels.
    // `alike`: the regions are fair samples of one image (interleaved tiles),
    // so once one has finished, the pace of the finished ones foretells the
    // region in progress better than its own progress, whose forecast errs
    // most in its last pixels.
    void expectCost(const std::vector<double>& seconds, const std::vector<double>& rays, bool sharesOfTime = false,
                    bool alike = false);
    // The time left after `elapsed` seconds of rendering, with `fraction`
    // (regions finished plus the current one's share of pixels, over their
    // count) done and `rays` traced. Also notes the regions finished.
    double secondsLeft(double elapsed, double fraction, double rays);

private:
    using Clock = std::chrono::steady_clock;
    void show(double fraction, std::uint64_t rays);
    void draw(const std::string& line);  // over the last line drawn; called with mutex_ held

    bool enabled_;
    // One way of predicting the regions' cost: expected cost before each
    // region and of all, and how far off its predictions of the finished
    // regions were (the sum of |log(predicted / taken)|).
    struct CostModel {
        std::vector<double> cumulative;
        double error = 0.0;
        // Seconds a unit of cost, as the first `regions` regions took it.
        double pace(std::size_t regions, double seconds) const;
    };
    const CostModel& bestModel() const;
    // How far the current region is, 0 to 1, from its share of pixels
    // finished and the rays traced in it.
    double regionProgress(double pixels, double rays) const;
    CostModel time_, rays_;
    bool sharesOfTime_ = false;
    bool alike_ = false;
    std::size_t regionsDone_ = 0;
    double secondsWhenDone_ = 0.0;       // the render's time when the last finished region ended
    double raysWhenDone_ = 0.0;          // and its rays traced by then
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
