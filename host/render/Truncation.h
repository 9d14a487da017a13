// What a render's cut-offs may have cost. SPEC §4 defines the exact image as
// the limit of the ray tree; a renderer stops somewhere (depth limit, weight
// cut-off, tree budget) and every ray it does not trace carries a known
// weight w. Whatever that ray would have returned is at most the scene's
// radiance bound R, so the pixel lost at most w·R in each channel. Every term
// of the sum is >= 0, so the exact colour lies in [value, value + w·R]; after
// SPEC §6's clamp, in [value, min(1, value + w·R)].
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "scene/Scene.h"

namespace snell {

// The largest radiance any ray can return in a scene, per channel. A hit on a
// sphere of material m returns its local term, at most L_m = I_a·kd +
// Σ_j I_j·(kd + ks) (N·L <= 1, (R·V)^p <= 1, SPEC §4.3), plus its children's
// light, which carry at most g_m = ks + kt of its weight (a totally reflected
// ray carries both, SPEC §4.5); a miss returns the background B. So any R
// with R >= B and R >= L_m + g_m·R for every m bounds every ray (by induction
// over the tree's depth): the least is R = max(B, max_m L_m/(1 − g_m)), each
// material its own geometric series, where all g_m < 1. (A bright diffuse
// floor beside dim glass of g = 0.95 gets R near the floor's L, not 20 times
// it.) Where some g_m >= 1 (SPEC §4 "amplifying materials", or ks + kt = 1)
// light need not decay: R = +inf. `local` and `gain` are the largest L_m
// and g_m, with B.
struct RadianceBound {
    glm::dvec3 local{0.0};     // max(B, max_m L_m): the most light one hit returns
    glm::dvec3 gain{0.0};      // max_m g_m
    glm::dvec3 radiance{0.0};  // R, +inf where some g_m >= 1 (and local > 0)
    bool finite() const;
};
RadianceBound radianceBound(const Scene& scene);

// What is known of one pixel's exact colour after one or more steps of its
// ray tree (each with its own cut-off): every step's colour is a lower
// bound, as every term of the sum is >= 0, and its colour plus the light it
// dropped (dropped weight times R) an upper bound. The pixel keeps the largest
// lower and the smallest upper bound of each channel, clamped to [0, 1] where
// the clamp makes them final (SPEC §6). Its bound is the widest gap.
struct PixelEstimate {
    glm::dvec3 lower{0.0};  // the colour reported (unclamped)
    glm::dvec3 upper{std::numeric_limits<double>::infinity()};

    // One step: `sum` its colour and `droppedLight` the most light of the
    // rays it did not trace (their weights times R, or each ray's own bound:
    // render/Reach.h), both summed over `samples`.
    void add(const glm::dvec3& sum, const glm::dvec3& droppedLight, double samples);
    // On the clamped colour; a channel whose upper bound is infinite is
    // bounded by 1 − lower only, and is `unbounded`.
    double bound() const;
    bool unbounded() const;
};

// The bound of a pixel that only the clamp bounds, its colour on either side
// of the exact one (an undecided decision where R is infinite: the light of
// either outcome may be anything): each clamped channel may be off by as much
// as it lies from 0 or from 1, whichever is farther.
inline double clampOnlyBound(const glm::dvec3& colour) {
    const glm::dvec3 c = glm::clamp(colour, 0.0, 1.0);
    const glm::dvec3 widest = glm::max(c, 1.0 - c);
    return std::max({widest.r, widest.g, widest.b});
}

// SPEC §6 clamps each channel to [0, 1]. Every term of a pixel's sum is >= 0,
// so the exact colour is at least the computed one less what the computed sum
// may hold that the exact one does not (`excess`: the light of rays below an
// undecided decision, of undecided shadow rays, and rounding). Where that
// still reaches 1 in every channel, the exact pixel is white as the computed
// one is: no undecided decision and no rounding can reach the output. (The
// subtraction's own rounding, relative 2^-53, is taken off the colour.)
inline bool whiteEitherWay(const glm::dvec3& colour, double excess) {
    return std::min({colour.r, colour.g, colour.b}) * (1.0 - 0x1p-50) - excess >= 1.0;
}

// The error of a pixel that cannot be certified (light dropped where it need
// not decay), estimated after each step of the cut-off from how far the step
// moved its colour and how the weight it has not traced yet (in channels not
// yet saturated) changed: where both shrink, by ratios up to rho < 1 a step,
// the steps still to come add about change · rho / (1 − rho), a geometric
// series; the estimate is that plus the last change itself, and at least the
// untraced weight times the most light a single hit returns (its children
// aside). Where the weight not traced does not shrink (light trapped in an
// amplifying material) there is no estimate: the pixel goes on. An estimate,
// not a bound (docs/accuracy.md measures how it holds).
struct ErrorEstimate {
    glm::dvec3 last{0.0};  // the colour after the last step, clamped (SPEC §6)
    double lastChange = std::numeric_limits<double>::infinity();
    double previousChange = std::numeric_limits<double>::infinity();
    double lastWeight = std::numeric_limits<double>::infinity();      // not traced after the last step
    double previousWeight = std::numeric_limits<double>::infinity();  // and after the one before
    int steps = 0;

    // The pixel's colour after a step, and the weight it has not traced (per
    // sample) times the most light one hit returns (RadianceBound::local).
    void add(const glm::dvec3& colour, const glm::dvec3& notTracedLight);
    double error() const;  // +inf while unknown (fewer than three steps) or not shrinking
};

// Where light can grow without end (SPEC §4 amplifying materials), per
// material. A ray's weight grows only at a hit whose one child carries more
// than the ray: a reflection of ks > 1, a refraction of kt > 1, or a total
// internal reflection, which carries ks + kt. Growing without end takes such
// hits over and over, and a sphere makes that certain in one way: inside it,
// every chord meets the surface at the angle of the last one, so a ray once
// reflected totally inside it is reflected totally for ever, gaining at every
// bounce where ks + kt > 1 (an orbit). That needs a refractive index above
// that of the medium a ray leaving the sphere enters (by the medium stack,
// SPEC §4.5: a refractive sphere around it or crossing it, else air), and a
// ray inside it at more than the critical angle: one that a refraction into
// it cannot make (it leaves at the angle it came in at), so something must
// turn it there, a surface inside or across it, or the eye inside it; an
// ellipsoid turns its own rays. Total internal reflection off a sphere from
// outside sends the ray away, and a path repeats it only by way of other
// surfaces at other angles, as chance has it: a transient, not an orbit (on
// scenes/glass.scn, whose air bubble in water reflects so with
// ks + kt = 1.05, no path grew by more than 4.3x). So a material "traps"
// light where some sphere of it has ks > 1 or kt > 1 in a channel, or
// ks + kt > 1 where such an orbit can form; placements are judged by bounding
// balls, and what is not sure counts as a trap.
std::vector<bool> growthTraps(const Scene& scene, const glm::dvec3& eye);
// The deepest medium stack any renderer keeps (the shader's,
// SNELL_MAX_MEDIA_LIMIT); deeper, the outermost medium is forgotten.
inline constexpr int kMediaStackLimit = 16;

// A pixel whose trees met a trap (growthTraps) may hide a diverging series
// behind steps that seem to settle: it stops on its estimated error only
// within this as well as the tolerance (1/100 of an 8-bit step, the limit
// reference's tolerance), and goes on below the floor until it saturates.
inline constexpr double kAmplifiedEstimate = 0.01 / 255.0;

// The most rays one sample's tree can hold under a depth limit D, a weight
// cut-off w and no tree budget, from the materials alone: level d of the tree
// holds at most 2^d rays (1 where no material both reflects and refracts), and (as children carry at most g = max(ks + kt) of
// their parent's weight) their weights sum to at most g^d, so at most
// g^d / w of them reach the cut-off. Returned as log2 of the count (+inf: no
// bound), with the sphere whose material has the largest g.
struct TreeSizeBound {
    double log2Rays = 0.0;
    double gain = 0.0;              // g
    std::size_t sphere = 0;         // a sphere with that material
};
TreeSizeBound treeSizeBound(const Scene& scene, int maxDepth, double minWeight);

// How a pixel's tree ended, as its renderer reports it.
struct PixelTruncation {
    int x = 0, y = 0;
    double bound = 0.0;           // the bound on its lost light
    bool unbounded = false;       // that light has no finite bound
    bool overBudget = false;      // stopped by the tree budget, not finished
    bool overTolerance = false;   // still above the tolerance at the floor cut-off
    bool estimated = false;       // unbounded, stopped by its estimated error (ErrorEstimate)
    // Where unbounded, the last estimate of its error made (+inf: none),
    // within the tolerance or not; the GPU reports those it stopped on only.
    double estimatedError = std::numeric_limits<double>::infinity();
    bool droppedGrowing = false;  // dropped light that may grow for want of room (the GPU's frontier or stack)
    // A decision of its trees was within its rounding margin (render/Margins.h):
    // its bound is widened to cover both outcomes, on both sides of the colour.
    bool undecided = false;
    bool retraced = false;        // the GPU's float decisions were undecided: re-traced by the CPU reference
    int retracedSamples = 0;      // of its samples, those re-traced (all, or those whose light hung on them)
};

// A render's truncation, summed over its pixels.
struct TruncationReport {
    double maxBound = 0.0;
    double sumBound = 0.0;
    std::uint64_t pixels = 0;
    std::uint64_t unbounded = 0;     // pixels whose lost light has no finite bound
    std::uint64_t overBudget = 0;    // pixels stopped by the tree budget, not finished
    std::uint64_t overTolerance = 0; // pixels still above the tolerance when the cut-off reached its floor
    std::uint64_t estimated = 0;     // unbounded pixels stopped by their estimated error (ErrorEstimate)
    std::uint64_t droppedGrowing = 0; // unbounded pixels, over the tolerance and unestimated, that dropped
                                      // light that may grow for want of room (the GPU's frontier or stack)
    std::uint64_t undecided = 0;     // pixels whose bound covers an undecided decision (widened)
    std::uint64_t undecidedUnbounded = 0;  // of those, pixels left with no finite bound by that alone
    std::uint64_t retraced = 0;      // pixels the GPU left undecided, re-traced by the CPU reference
    std::uint64_t retracedSamples = 0;  // and their samples re-traced
    double maxEstimate = 0.0;        // the largest estimated error of the estimated pixels
    int deepest = 0;                 // the deepest ray traced (generations below the primary ray)
    static constexpr std::size_t kExamples = 8;
    // The first few, (x, y), of the unbounded pixels that neither claim an
    // estimate nor dropped growing light (their colour had not settled), of
    // those over budget, and of those that dropped growing light.
    std::vector<std::array<int, 2>> unsettledExamples;
    std::vector<std::array<int, 2>> overBudgetExamples;
    std::vector<std::array<int, 2>> droppedGrowingExamples;

    double meanBound() const { return pixels ? sumBound / double(pixels) : 0.0; }
    // Unbounded pixels that neither claim an estimate nor dropped growing light,
    // nor have no bound only for a decision rounding may have flipped.
    std::uint64_t unsettled() const {
        return unbounded - std::min(unbounded, estimated + droppedGrowing + undecidedUnbounded);
    }
    void add(const PixelTruncation& pixel);
    void merge(const TruncationReport& other);
};

}  // namespace snell
