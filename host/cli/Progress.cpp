#include "cli/Progress.h"

#include <algorithm>
#include <cstdio>

#include <unistd.h>

namespace snell::cli {

Progress::Progress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)), start_(Clock::now()) {}

std::function<void(double, std::uint64_t)> Progress::callback() {
    if (!enabled_) return {};
    return [this](double fraction, std::uint64_t rays) { show(fraction, rays); };
}

void Progress::show(double fraction, std::uint64_t rays) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!enabled_) return;
    const auto now = Clock::now();
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
    if (fraction > 0.01 && fraction < 1.0) line += ", ~" + formatDuration(secondsLeft(elapsed, fraction, rays)) + " left";
    if (rays > 0 && elapsed > 0.0) {
        std::snprintf(text, sizeof text, ", %.3g Mrays/s", double(rays) / elapsed * 1e-6);
        line += text;
    }
    width_ = std::max(width_, line.size());
    std::fprintf(stderr, "%-*s", int(width_), line.c_str());
    std::fflush(stderr);
}

double Progress::secondsLeft(double elapsed, double fraction, std::uint64_t rays) const {
    // While the estimate holds; past it (it was low), the pixels' pace.
    if (expectedRays_ > 0.0 && rays > 0 && double(rays) < expectedRays_)
        return elapsed * (expectedRays_ - double(rays)) / double(rays);
    return elapsed * (1.0 - fraction) / fraction;
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
