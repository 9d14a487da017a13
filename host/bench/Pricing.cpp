// Pricing the default: its dispatch time over the fastest fixed tree's as accurate.
#include "bench/BenchParts.h"

#include <algorithm>
#include <cmath>
#include <sstream>


namespace snell::bench {

Price priceOf(const std::vector<Result>& results, std::size_t def, const std::vector<std::size_t>& tried) {
    const Result& d = results[def];
    Price p;
    p.scene = d.scene;
    p.defaultMs = d.dispatchMs.median;
    p.defaultMean = d.error.meanAbsError;
    p.defaultBad = d.error.badPixels;
    const TruncationReport& t = d.bound;
    p.pixels = t.pixels;
    p.estimated = t.estimated;
    p.overTolerance = t.overTolerance;
    p.overBudget = t.overBudget;
    // An estimated pixel is not over the tolerance; every other pixel is certified.
    p.certified = t.pixels - std::min(t.pixels, t.estimated + t.overTolerance);
    p.unboundedNotEstimated = t.unbounded - std::min(t.unbounded, t.estimated);
    p.tried = int(tried.size());
    std::optional<std::size_t> fastest, slowest;
    for (std::size_t i : tried) {
        const double ms = results[i].dispatchMs.median;
        if (asAccurate(results[i], d) && (!fastest || ms < results[*fastest].dispatchMs.median)) fastest = i;
        if (!slowest || ms > results[*slowest].dispatchMs.median) slowest = i;
    }
    const std::optional<std::size_t> setter = fastest ? fastest : slowest;
    if (!setter) return p;
    const Result& f = results[*setter];
    p.upperBound = !fastest;
    p.price = p.defaultMs / f.dispatchMs.median;
    p.fixed = f.setting.name;
    p.fixedMs = f.dispatchMs.median;
    p.fixedMean = f.error.meanAbsError;
    p.fixedBad = f.error.badPixels;
    return p;
}

// The price again from the default and the fixed tree that sets it timed side
// by side (SceneRun::measureSideBySide): chosen as the fastest of many noisy
// medians, that tree's own median is biased low (the winner's curse), and
// the sweep timed the default before the trees, minutes apart on a big scene.
constexpr int kSideBySideRuns = 5;  // a block's timed renders, at the least
void retimePrice(SceneRun& run, const std::vector<Result>& results, std::size_t def, Price& p) {
    if (std::isnan(p.price)) return;
    const auto setter = std::find_if(results.begin() + std::ptrdiff_t(def), results.end(),
                                     [&](const Result& r) { return r.setting.name == p.fixed && r.setting.front; });
    if (setter == results.end()) return;
    const double pairMs = results[def].dispatchMs.median + setter->dispatchMs.median;
    const int runs = timedRuns(kSideBySideRuns, pairMs * SceneRun::kSideBySideRounds, run.quick);
    const auto [defaultMs, fixedMs] = run.measureSideBySide(results[def].setting, setter->setting, runs);
    if (!(defaultMs.median > 0.0) || !(fixedMs.median > 0.0)) return;
    p.defaultMs = defaultMs.median;
    p.fixedMs = fixedMs.median;
    p.price = p.defaultMs / p.fixedMs;
    p.sideBySideRuns = runs * SceneRun::kSideBySideRounds;
}

std::string brief(double v) {  // three significant digits, for the log
    std::ostringstream s;
    s.precision(3);
    s << v;
    return s.str();
}

// "price of the default 1.23x (fixed min-weight 0.00391: 12.3 ms, mean 0.02/255, 3 bad); ..."
std::string describe(const Price& p) {
    std::ostringstream s;
    if (std::isnan(p.price)) {
        s << "price of the default: no fixed tree measured";
    } else {
        s << "price of the default " << (p.upperBound ? "< " : "") << brief(p.price) << "x ("
          << (p.upperBound ? "no fixed tree as accurate; slowest tried " : "") << p.fixed << ": "
          << brief(p.fixedMs) << " ms, mean " << brief(p.fixedMean) << "/255, " << p.fixedBad << " bad";
        if (p.sideBySideRuns)
            s << "; default " << brief(p.defaultMs) << " ms; timed side by side, " << p.sideBySideRuns << " runs each";
        s << ")";
    }
    s << "; default mean " << brief(p.defaultMean) << "/255, " << p.defaultBad << " bad; pixels " << p.certified
      << " certified, " << p.estimated << " estimated, " << p.unboundedNotEstimated << " unbounded not estimated";
    if (p.overBudget) s << ", " << p.overBudget << " over budget";
    s << " of " << p.pixels << "; " << p.tried << " fixed trees tried";
    return s.str();
}


PriceSummary summarizePrices(const std::vector<Price>& prices) {
    PriceSummary s;
    double sumLog = 0.0;
    for (const Price& p : prices) {
        if (!(p.price > 0.0) || !std::isfinite(p.price)) continue;
        ++s.scenes;
        s.upperBounds += p.upperBound;
        sumLog += std::log(p.price);
        if (!s.worst || p.price > s.worst->price) s.worst = p;
    }
    if (s.scenes) s.geometricMean = std::exp(sumLog / s.scenes);
    return s;
}

std::string describe(const PriceSummary& s) {
    if (!s.worst) return "price of the default: no scene priced";
    std::ostringstream o;
    o << "price of the default: geometric mean " << (s.upperBounds ? "< " : "") << brief(s.geometricMean)
      << "x over " << s.scenes << " scenes";
    if (s.upperBounds) o << " (" << s.upperBounds << " of them upper bounds)";
    o << "; worst " << (s.worst->upperBound ? "< " : "") << brief(s.worst->price) << "x on " << s.worst->scene
      << " (" << s.worst->fixed << ")";
    return o.str();
}

}  // namespace snell::bench
