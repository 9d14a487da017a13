#include "cli/Progress.h"

#include <algorithm>
#include <cstdio>

#include <unistd.h>

namespace snell::cli {

Progress::Progress(bool enabled)
    : enabled_(enabled && ::isatty(STDERR_FILENO)), renderStart_(Clock::now()), start_(Clock::now()) {}

std::function<void(double, std::uint64_t)> Progress::callback() {
    if (!enabled_) return {};
    return [this](double fraction, std::uint64_t rays) { show(fraction, rays); };
}

void Progress::show(double fraction, std::uint64_t rays) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!enabled_) return;
    const auto now = Clock::now();
    // Every report counts for the estimate (it notes the regions finished), a few a second are shown.
    const double left = secondsLeft(std::chrono::duration<double>(now - renderStart_).count(), fraction);
    if (fraction < 1.0 && now - last_ < std::chrono::milliseconds(250)) return;
    last_ = now;
    shown_ = true;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    constexpr int kWidth = 24;
    const int filled = std::clamp(int(fraction * kWidth + 0.5), 0, kWidth);
    std::string line = "\rsnell: [" + std::string(filled, '#') + std::string(kWidth - filled, '.') + "] ";
    char text[160];
    std::snprintf(text, sizeof text, "%5.1f%%  %s elapsed", 100.0 * fraction, formatDuration(elapsed).c_str());
    line += text;
    if (fraction > 0.01 && fraction < 1.0) line += ", ~" + formatDuration(left) + " left";
    if (rays > 0 && elapsed > 0.0) {
        std::snprintf(text, sizeof text, ", %.3g Mrays/s", double(rays) / elapsed * 1e-6);
        line += text;
    }
    width_ = std::max(width_, line.size());
    std::fprintf(stderr, "%-*s", int(width_), line.c_str());
    std::fflush(stderr);
}

void Progress::expectCost(std::vector<double> regions) {
    std::lock_guard<std::mutex> lock(mutex_);
    cumulativeCost_.assign(1, 0.0);
    for (double c : regions) cumulativeCost_.push_back(cumulativeCost_.back() + c);
    if (cumulativeCost_.back() <= 0.0) cumulativeCost_.clear();
    regionsDone_ = 0;
    secondsWhenDone_ = 0.0;
    renderStart_ = Clock::now();
}

double Progress::secondsLeft(double elapsed, double fraction) {
    if (cumulativeCost_.empty() || elapsed <= 0.0) return elapsed * (1.0 - fraction) / fraction;
    const std::size_t regions = cumulativeCost_.size() - 1;
    const auto done = std::min(regions, std::size_t(std::max(0.0, fraction) * double(regions) + 1e-9));
    if (done > regionsDone_) {
        regionsDone_ = done;
        secondsWhenDone_ = elapsed;
    }
    const double expectedDone = cumulativeCost_[regionsDone_], expectedAll = cumulativeCost_.back();
    // How the finished regions' time compared with their expectation
    // (before the first is finished, the expectation as it is).
    const double scale = regionsDone_ > 0 && expectedDone > 0.0 ? secondsWhenDone_ / expectedDone : 1.0;
    const double ahead = scale * (expectedAll - expectedDone) - (elapsed - secondsWhenDone_);
    // Past its expectation, the current region is taken to be nearly done.
    return std::max(ahead, 0.02 * scale * (expectedAll - expectedDone));
}

void Progress::done() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shown_) std::fprintf(stderr, "\r%*s\r", int(width_), "");
    shown_ = false;
    enabled_ = false;
}

std::string formatDuration(double seconds) {
    char text[32];
    if (seconds < 60.0) std::snprintf(text, sizeof text, "%.1f s", seconds);
    else if (seconds < 3600.0) std::snprintf(text, sizeof text, "%d min %02d s", int(seconds / 60), int(seconds) % 60);
    else std::snprintf(text, sizeof text, "%d h %02d min", int(seconds / 3600), int(seconds / 60) % 60);
    return text;
}

}  // namespace snell::cli
