#include "cli/Progress.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <thread>

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
    const double left = secondsLeft(std::chrono::duration<double>(now - renderStart_).count(), fraction, double(rays));
    if (fraction < 1.0 && now - last_ < std::chrono::milliseconds(250)) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rendering = std::chrono::duration<double>(now - renderStart_).count();
    constexpr int kWidth = 24;
    const int filled = std::clamp(int(fraction * kWidth + 0.5), 0, kWidth);
    std::string line = "\rsnell: [" + std::string(filled, '#') + std::string(kWidth - filled, '.') + "] ";
    char text[160];
    std::snprintf(text, sizeof text, "%5.1f%%  %s elapsed", 100.0 * fraction, formatDuration(elapsed).c_str());
    line += text;
    if (fraction > 0.01 && fraction < 1.0) line += ", ~" + formatDuration(left) + " left";
    if (rays > 0 && rendering > 0.0) {
        std::snprintf(text, sizeof text, ", %.3g Mrays/s", double(rays) / rendering * 1e-6);
        line += text;
    }
    draw(line);
}

void Progress::draw(const std::string& line) {
    shown_ = true;
    width_ = std::max(width_, line.size());
    std::fprintf(stderr, "%-*s", int(width_), line.c_str());
    std::fflush(stderr);
}

void Progress::during(const std::string& what, const std::function<void()>& work) {
    if (!enabled()) return work();
    constexpr auto kQuiet = std::chrono::milliseconds(250), kTick = std::chrono::milliseconds(100);
    std::mutex m;
    std::condition_variable stop;
    bool finished = false;
    const auto start = Clock::now();
    std::thread ticker([&] {
        std::unique_lock<std::mutex> lock(m);
        while (!stop.wait_for(lock, kTick, [&] { return finished; })) {
            const auto now = Clock::now();
            if (now - start < kQuiet) continue;
            std::lock_guard<std::mutex> bar(mutex_);
            if (enabled_)
                draw("\rsnell: " + what + "... " + formatDuration(std::chrono::duration<double>(now - start).count()));
        }
    });
    auto join = [&] {
        {
            std::lock_guard<std::mutex> lock(m);
            finished = true;
        }
        stop.notify_all();
        ticker.join();
    };
    try {
        work();
    } catch (...) {
        join();
        throw;
    }
    join();
}

void Progress::renderStarts() {
    std::lock_guard<std::mutex> lock(mutex_);
    renderStart_ = Clock::now();
}

void Progress::expectCost(const std::vector<double>& seconds, const std::vector<double>& rays, bool sharesOfTime,
                          bool alike) {
    std::lock_guard<std::mutex> lock(mutex_);
    sharesOfTime_ = sharesOfTime;
    alike_ = alike;
    for (auto [model, costs] : {std::pair{&time_, &seconds}, std::pair{&rays_, &rays}}) {
        model->cumulative.assign(1, 0.0);
        for (double c : *costs) model->cumulative.push_back(model->cumulative.back() + c);
        model->error = 0.0;
    }
    // The probe's own time is the pace of its rays until a region finishes.
    const double probeSeconds = time_.cumulative.back(), probeRays = rays_.cumulative.back();
    if (!(probeSeconds > 0.0) || !(probeRays > 0.0) || seconds.size() != rays.size()) {
        time_.cumulative.clear();
        rays_.cumulative.clear();
    }
    regionsDone_ = 0;
    secondsWhenDone_ = 0.0;
    raysWhenDone_ = 0.0;
    renderStart_ = Clock::now();
}

double Progress::CostModel::pace(std::size_t regions, double seconds) const {
    if (regions > 0 && cumulative[regions] > 0.0) return seconds / cumulative[regions];
    return cumulative.back() > 0.0 ? 1.0 : 0.0;  // seconds: the probe's own measure
}

const Progress::CostModel& Progress::bestModel() const { return rays_.error < time_.error ? rays_ : time_; }

double Progress::secondsLeft(double elapsed, double fraction, double rays) {
    if (time_.cumulative.empty() || elapsed <= 0.0) return elapsed * (1.0 - fraction) / fraction;
    const std::size_t regions = time_.cumulative.size() - 1;
    const auto done = std::min(regions, std::size_t(std::max(0.0, fraction) * double(regions) + 1e-9));
    if (done > regionsDone_) {
        // Score each model on the regions just finished, predicted at the
        // pace of those before them (the first region only sets the pace).
        if (regionsDone_ > 0) {
            const double taken = elapsed - secondsWhenDone_;
            for (CostModel* m : {&time_, &rays_}) {
                const double predicted = m->pace(regionsDone_, secondsWhenDone_) *
                                         (m->cumulative[done] - m->cumulative[regionsDone_]);
                if (predicted > 0.0 && taken > 0.0) m->error += std::abs(std::log(predicted / taken));
            }
        }
        regionsDone_ = done;
        secondsWhenDone_ = elapsed;
        raysWhenDone_ = rays;
    }
    if (regionsDone_ == regions) return 0.0;
    const CostModel& m = bestModel();
    const double costDone = m.cumulative[regionsDone_], costCurrent = m.cumulative[regionsDone_ + 1] - costDone;
    const double costAfter = m.cumulative.back() - costDone - costCurrent;
    const double inRegion = elapsed - secondsWhenDone_;
    const double share = fraction * double(regions) - double(regionsDone_);
    const double progress = sharesOfTime_ ? std::clamp(share, 0.0, 0.999) : regionProgress(share, rays - raysWhenDone_);
    if (alike_ && regionsDone_ > 0) {
        // Alike regions: the current one takes what the finished ones took,
        // unless it has run past that (then its own pace says).
        const double pace = m.pace(regionsDone_, secondsWhenDone_);
        const double expectedLeft = pace * costCurrent - inRegion;
        const double ownLeft = progress > 0.01 ? inRegion * (1.0 - progress) / progress : 0.0;
        const double paceNow = elapsed / (costDone + costCurrent);
        return expectedLeft > 0.0 ? pace * costAfter + expectedLeft : ownLeft + paceNow * costAfter;
    }
    // The pace of the work done so far, the current region's share of its
    // cost included once it has made some progress (the probe's time
    // overstates a small probe whose few expensive pixels ran alone); before
    // that, the finished regions', or with none, the probe's.
    double pace = m.pace(regionsDone_, secondsWhenDone_);
    if (progress > 0.05 && inRegion > 0.0 && costCurrent > 0.0) pace = elapsed / (costDone + progress * costCurrent);
    else if (regionsDone_ == 0 && &m == &rays_) pace = time_.cumulative.back() / rays_.cumulative.back();
    // A current region past its expectation sets the pace of the rest as if it ended now.
    const double paceNow = costDone + costCurrent > 0.0 ? elapsed / (costDone + costCurrent) : pace;
    // The current region: its expectation at that pace, and its own pace over
    // its progress, trusted in proportion to that progress (a share of its
    // time is the renderer's own forecast, trusted fully from a fifth on);
    // one past its expectation with no progress shown is taken to be nearly
    // done.
    const double expectedLeft = std::max(0.0, pace * costCurrent - inRegion);
    const double ownLeft = progress > 0.01 ? inRegion * (1.0 - progress) / progress : expectedLeft;
    const double trust = sharesOfTime_ ? std::min(1.0, progress / 0.2) : progress;
    const double currentLeft = progress > 0.0 ? (1.0 - trust) * expectedLeft + trust * ownLeft
                                              : std::max(expectedLeft, 0.02 * paceNow * costCurrent);
    return std::max(pace * costAfter + currentLeft, paceNow * costAfter);
}

double Progress::regionProgress(double pixels, double rays) const {
    pixels = std::clamp(pixels, 0.0, 1.0);
    const std::size_t k = regionsDone_;
    // The region's expected rays: the probe's, scaled as the finished regions' rays ran against theirs.
    const double scale = k > 0 && rays_.cumulative[k] > 0.0 ? raysWhenDone_ / rays_.cumulative[k] : 1.0;
    const double expected = (rays_.cumulative[k + 1] - rays_.cumulative[k]) * scale;
    if (!(rays > 0.0) || !(expected > 0.0)) return std::min(pixels, 0.999);
    return std::min(rays / (rays + (1.0 - pixels) * expected), 0.999);
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
