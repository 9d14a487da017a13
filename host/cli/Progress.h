// A progress bar on standard error, only when it is a terminal: the pixels
// finished, the time so far, an estimate of the time left and the rays a
// second, a few times a second; erased when the render ends.
//
// The time left: a render's cost is uneven over the image (sky above, glass
// below), so extrapolating the pixels done misleads. Given the rays the whole
// render will trace (estimated from a sparse render of the same image,
// expectRays), the time left is the time so far scaled by the rays still to
// trace; without it, by the pixels.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

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
    void expectRays(double total) { expectedRays_ = total; }
    // The time left after `elapsed` seconds, `fraction` of the pixels and `rays` traced.
    double secondsLeft(double elapsed, double fraction, std::uint64_t rays) const;

private:
    using Clock = std::chrono::steady_clock;
    void show(double fraction, std::uint64_t rays);

    bool enabled_;
    double expectedRays_ = 0.0;
    bool shown_ = false;
    std::size_t width_ = 0;
    std::mutex mutex_;
    Clock::time_point start_;
    Clock::time_point last_{};
};

// "12.3 s", "4 min 05 s", "2 h 10 min".
std::string formatDuration(double seconds);

}  // namespace snell::cli
