#include "render/Truncation.h"

#include "render/Placement.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace snell {

bool RadianceBound::finite() const {
    return std::isfinite(radiance.x) && std::isfinite(radiance.y) && std::isfinite(radiance.z);
}

RadianceBound radianceBound(const Scene& scene) {
    RadianceBound b;
    b.local = scene.background;
    glm::dvec3 lights(0.0);
    for (const Light& light : scene.lights) lights += light.colour;
    // The least R with R >= B and R >= L_m + g_m·R for every material m.
    glm::dvec3 series = scene.background;
    for (const Material& m : scene.materials) {
        const glm::dvec3 local = scene.ambient * m.kd + lights * (m.kd + m.ks);
        const glm::dvec3 gain = m.gain();
        b.local = glm::max(b.local, local);
        b.gain = glm::max(b.gain, gain);
        for (int c = 0; c < 3; ++c)
            if (gain[c] < 1.0) series[c] = std::max(series[c], local[c] / (1.0 - gain[c]));
    }
    for (int c = 0; c < 3; ++c) {
        if (b.local[c] == 0.0) b.radiance[c] = 0.0;  // no light in this channel at all
        else if (b.gain[c] < 1.0) b.radiance[c] = series[c];
        else b.radiance[c] = std::numeric_limits<double>::infinity();
    }
    return b;
}

void PixelEstimate::add(const glm::dvec3& sum, const glm::dvec3& droppedLight, double samples) {
    for (int c = 0; c < 3; ++c) {
        const double value = sum[c] / samples;
        lower[c] = std::max(lower[c], value);
        upper[c] = std::min(upper[c], value + droppedLight[c] / samples);
    }
}

double PixelEstimate::bound() const {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::min(upper[c], 1.0) - std::min(lower[c], 1.0));
    return std::max(worst, 0.0);
}

bool PixelEstimate::unbounded() const {
    for (int c = 0; c < 3; ++c)
        if (std::isinf(upper[c]) && lower[c] < 1.0) return true;
    return false;
}

void ErrorEstimate::add(const glm::dvec3& colour, const glm::dvec3& notTracedLight) {
    const glm::dvec3 clamped = glm::min(colour, glm::dvec3(1.0));
    double weight = 0.0;  // in the channels that can still move
    for (int c = 0; c < 3; ++c)
        if (clamped[c] < 1.0) weight = std::max(weight, notTracedLight[c]);
    if (steps > 0) {
        previousChange = lastChange;
        lastChange = std::max({std::abs(clamped.x - last.x), std::abs(clamped.y - last.y), std::abs(clamped.z - last.z)});
    }
    previousWeight = lastWeight;
    lastWeight = weight;
    last = clamped;
    ++steps;
}

double ErrorEstimate::error() const {
    if (steps < 3 || !(lastWeight < previousWeight)) return std::numeric_limits<double>::infinity();
    const double rho = std::max(lastChange / previousChange, lastWeight / previousWeight);
    if (!(rho < 1.0) && lastChange > 0.0) return std::numeric_limits<double>::infinity();
    return std::max(lastWeight, lastChange > 0.0 ? lastChange / (1.0 - rho) : 0.0);
}

namespace {

// Sphere pairs the analysis looks at before it takes every sphere for a trap.
constexpr double kMaxPairs = 1e8;

// Whether an orbit of total internal reflection can form inside sphere i
// (growthTraps): a ray inside it must meet its surface at more than the
// critical angle, so something must turn rays inside it, and a ray leaving
// it must enter a medium of a lower refractive index.
bool orbitInside(const Scene& scene, std::size_t i, const glm::dvec3& eye) {
    const Sphere& s = scene.spheres[i];
    const Ball ball = boundingBall(s);
    // An ellipsoid's chords meet its surface at changing angles; rays from an
    // eye inside start at any angle.
    bool turned = !s.isTrueSphere || holds(ball, eye);
    bool air = false;  // a ray leaving it may enter air
    double least = std::numeric_limits<double>::infinity();
    int containers = 0;
    for (std::size_t j = 0; j < scene.spheres.size(); ++j) {
        if (j == i) continue;
        const Sphere& q = scene.spheres[j];
        const Placement p = placement(ball, boundingBall(q));
        if (p == Placement::Apart) continue;
        // Any surface in it (an opaque one too) can turn a ray.
        if (p != Placement::Inside || !q.isTrueSphere) turned = true;
        const Material& m = scene.materials[q.material];
        if (!m.refracts() || p == Placement::Around) continue;  // not a medium around it
        least = std::min(least, m.eta);
        if (p == Placement::Inside && q.isTrueSphere) {
            ++containers;
            // Primary rays start in air even inside a sphere (SPEC §4.5):
            // their stack lacks it, and a ray leaving may enter air.
            if (holds(boundingBall(q), eye)) air = true;
        }
    }
    // Without a sphere around it every surface point may face air; a stack
    // deeper than any renderer keeps forgets its outermost medium.
    if (containers == 0 || containers >= kMediaStackLimit) air = true;
    if (air) least = std::min(least, kAirEta);
    return turned && scene.materials[s.material].eta > least;
}

}  // namespace

std::vector<bool> growthTraps(const Scene& scene, const glm::dvec3& eye) {
    std::vector<bool> traps(scene.materials.size(), false);
    std::size_t candidates = 0;
    for (const Sphere& s : scene.spheres) candidates += scene.materials[s.material].amplifies();
    const bool tooMany = double(candidates) * double(scene.spheres.size()) > kMaxPairs;
    for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
        const Material& m = scene.materials[scene.spheres[i].material];
        if (traps[scene.spheres[i].material]) continue;
        bool grows = false;  // one child carries more than its ray
        for (int c = 0; c < 3; ++c) grows = grows || m.ks[c] > 1.0 || m.kt[c] > 1.0;
        traps[scene.spheres[i].material] =
            grows || (m.refracts() && m.amplifies() && (tooMany || orbitInside(scene, i, eye)));
    }
    return traps;
}

TreeSizeBound treeSizeBound(const Scene& scene, int maxDepth, double minWeight) {
    TreeSizeBound b;
    bool branches = false;  // a hit can have two children
    for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
        const Material& m = scene.materials[scene.spheres[i].material];
        branches = branches || (m.reflects() && m.refracts());
        const double g = m.largestGain();
        if (g > b.gain) {
            b.gain = g;
            b.sphere = i;
        }
    }
    if (b.gain == 0.0) return b;  // no secondary rays: one ray a sample
    // log2 of sum over d <= D of min(2^d, g^d / w), summed in the log domain.
    double total = -std::numeric_limits<double>::infinity();
    const double log2w = minWeight > 0.0 ? std::log2(minWeight) : -std::numeric_limits<double>::infinity();
    const double log2g = std::log2(b.gain);
    for (int d = 0; d <= maxDepth; ++d) {
        const double level = std::min(branches ? double(d) : 0.0, d * log2g - log2w);
        if (level < 0.0 && d > 0 && log2g <= 0.0) break;  // no ray this deep reaches the cut-off
        total = std::max(total, level) + std::log2(1.0 + std::exp2(-std::abs(total - level)));
        if (total > 1e4) return b.log2Rays = std::numeric_limits<double>::infinity(), b;
    }
    b.log2Rays = total;
    return b;
}

void TruncationReport::add(const PixelTruncation& p) {
    maxBound = std::max(maxBound, p.bound);
    sumBound += p.bound;
    ++pixels;
    overTolerance += p.overTolerance;
    if (p.unbounded) ++unbounded;
    undecided += p.undecided;
    retraced += p.retraced;
    retracedSamples += std::uint64_t(p.retracedSamples);
    if (p.estimated) {
        ++estimated;
        maxEstimate = std::max(maxEstimate, p.estimatedError);
    }
    if (p.droppedGrowing) {
        ++droppedGrowing;
        if (droppedGrowingExamples.size() < kExamples) droppedGrowingExamples.push_back({p.x, p.y});
    }
    const bool undecidedOnly = p.undecided && p.unbounded && !p.estimated && !p.droppedGrowing;
    undecidedUnbounded += undecidedOnly;
    if (p.unbounded && !p.estimated && !p.droppedGrowing && !undecidedOnly && unsettledExamples.size() < kExamples)
        unsettledExamples.push_back({p.x, p.y});
    if (p.overBudget) {
        ++overBudget;
        if (overBudgetExamples.size() < kExamples) overBudgetExamples.push_back({p.x, p.y});
    }
}

void TruncationReport::merge(const TruncationReport& o) {
    estimated += o.estimated;
    undecided += o.undecided;
    undecidedUnbounded += o.undecidedUnbounded;
    retraced += o.retraced;
    retracedSamples += o.retracedSamples;
    droppedGrowing += o.droppedGrowing;
    maxEstimate = std::max(maxEstimate, o.maxEstimate);
    maxBound = std::max(maxBound, o.maxBound);
    sumBound += o.sumBound;
    pixels += o.pixels;
    unbounded += o.unbounded;
    overBudget += o.overBudget;
    overTolerance += o.overTolerance;
    deepest = std::max(deepest, o.deepest);
    for (const auto& e : o.unsettledExamples)
        if (unsettledExamples.size() < kExamples) unsettledExamples.push_back(e);
    for (const auto& e : o.overBudgetExamples)
        if (overBudgetExamples.size() < kExamples) overBudgetExamples.push_back(e);
    for (const auto& e : o.droppedGrowingExamples)
        if (droppedGrowingExamples.size() < kExamples) droppedGrowingExamples.push_back(e);
}

}  // namespace snell
