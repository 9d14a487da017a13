#include "render/TruncationMessages.h"

#include <algorithm>
#include <cstdio>

namespace snell {
namespace {

// As the options take them back: %g keeps what a user types.
std::string number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", value);
    return text;
}

// ", e.g. (x, y), ...", or nothing where the renderer kept no coordinates.
std::string examples(const std::vector<std::array<int, 2>>& pixels, std::uint64_t count) {
    std::string s;
    for (const auto& p : pixels) {
        s += s.empty() ? "(" : ", (";
        s += std::to_string(p[0]) + ", " + std::to_string(p[1]) + ")";
    }
    if (s.empty()) return s;
    if (count > pixels.size()) s += ", ...";
    return ", e.g. " + s;
}

// A floor this much lower lets a pixel whose estimate has not settled take
// more steps; measured on scenes/glass.scn, 100x was not always enough for the
// CPU reference and cost little less than this (pixels stop on their estimates).
constexpr double kLowerFloor = 1e4;
// A depth limit this much higher, up to the default's safety cap.
constexpr int kDeeper = 4;

// Why a tolerance ladder stopped short of its tolerance, and the options that
// take its pixels further: a deeper cap where trees reached the depth limit the
// user set, a lower floor where there is one; the tolerance always, so that
// --depth and --min-weight stay cap and floor rather than a fixed tree.
struct StoppedShort {
    std::string where;
    std::string advice;  // empty where no option takes the pixels further (the tree budget stopped them)
};
StoppedShort stoppedShort(const TruncationReport& t, const TraceSettings& s) {
    const bool depthLimited = t.deepest >= s.maxDepth && s.maxDepth < kDefaultSettings.maxDepth;
    StoppedShort r;
    if (depthLimited) r.where = "their trees reached the depth limit " + std::to_string(s.maxDepth);
    else if (s.minWeight > 0.0) r.where = "the cut-off reached its floor " + number(s.minWeight);
    else r.where = "their trees reached the tree budget";
    if (depthLimited) r.advice += "--depth " + std::to_string(std::min(kDefaultSettings.maxDepth, kDeeper * s.maxDepth)) + " ";
    if (s.minWeight > 0.0) r.advice += "--min-weight " + number(s.minWeight / kLowerFloor) + " ";
    if (!r.advice.empty()) r.advice += "--tolerance " + number(s.tolerance);
    return r;
}

// Their untraced light (cut off, not lost: dropped_growing_pixels is another
// matter) has no finite bound.
constexpr const char* kNoFiniteBound =
    "no finite error bound (light of a material with ks + kt >= 1, which need not decay, was left untraced there, "
    "so only the clamp to 1 bounds them)";

// Tolerance ladders: pixels stopped on an estimate (a note: not a bound, but
// what was asked), and pixels that reached the end of the ladder above the
// tolerance, with or without a finite bound.
void ladderMessages(const TruncationReport& t, const TraceSettings& s, std::vector<std::string>& out) {
    if (t.estimated > 0)
        out.push_back("snell: note: " + std::to_string(t.estimated) + " pixel(s) have " + kNoFiniteBound +
                      ": each stopped when its estimated error was within the tolerance " + number(s.tolerance) +
                      " (largest " + number(t.maxEstimate) + "), an estimate, not a bound (--bound-image marks them)");
    const StoppedShort stop = stoppedShort(t, s);
    const std::string further = stop.advice.empty() ? "" : "; '" + stop.advice + "' traces them further, at more rays";
    if (t.unsettled() > 0)
        out.push_back("snell: warning: " + std::to_string(t.unsettled()) + " pixel(s) have " + kNoFiniteBound +
                      ", and their estimated error was not yet within the tolerance " + number(s.tolerance) + " when " +
                      stop.where + " (--bound-image shows where)" + further +
                      examples(t.unsettledExamples, t.unsettled()));
    // Over the tolerance with a finite bound: the rest of those over it.
    const std::uint64_t unboundedOver = t.unsettled() + t.droppedGrowing;
    const std::uint64_t bounded = t.overTolerance - std::min(t.overTolerance, unboundedOver);
    if (bounded > 0)
        out.push_back("snell: warning: " + std::to_string(bounded) + " pixel(s) may still be further than the "
                      "tolerance " + number(s.tolerance) + " from the exact image" +
                      (t.unbounded == 0 ? " (by at most " + number(t.maxBound) + ")" : std::string()) + " when " +
                      stop.where + " (--bound-image shows where)" + further);
}

// A fixed tree neither bounds nor estimates the light it drops where it need
// not decay; a tolerance (with the same depth and cut-off as cap and floor)
// estimates it, tracing no more than the fixed tree where no light can grow;
// the default (neither given) costs least.
void fixedTreeMessages(const TruncationReport& t, std::vector<std::string>& out) {
    if (t.unsettled() == 0) return;
    const std::string tolerance = number(kDefaultSettings.tolerance);
    out.push_back("snell: warning: " + std::to_string(t.unsettled()) + " pixel(s) have " + kNoFiniteBound +
                  ", and a fixed tree (--depth or --min-weight without --tolerance) does not estimate their error "
                  "(--bound-image shows where); '--tolerance " + tolerance +
                  "' traces each only until its estimated error is within " + tolerance +
                  " (0.5/255), with --depth and --min-weight as cap and floor (the default, without them, at the "
                  "least cost)" +
                  examples(t.unsettledExamples, t.unsettled()));
}

void budgetMessage(const TruncationReport& t, const TraceSettings& s, std::vector<std::string>& out) {
    if (t.overBudget == 0) return;
    const std::string tolerance = s.tolerance > 0.0 ? " --tolerance " + number(s.tolerance) : "";
    // Without a floor, a tree over materials that keep a ray's weight need
    // not end whatever the budget; with one, a larger budget goes further.
    const std::string advice =
        s.minWeight == 0.0 ? "with --min-weight 0 a tree need not end: '--min-weight " +
                                 number(kReferenceSettings.minWeight) + tolerance + "' gives it a floor"
                           : "'--tree-budget " + std::to_string(4 * s.treeBudget) + "' lets them go further";
    out.push_back("snell: warning: " + std::to_string(t.overBudget) + " pixel(s) reached the tree budget of " +
                  std::to_string(s.treeBudget) + " rays a sample and were stopped before their trees ended: " +
                  "--bound-image shows how far each may be from the exact image; " + advice +
                  examples(t.overBudgetExamples, t.overBudget));
}

// Decisions that rounding could have flipped (render/Margins.h), where even
// the arithmetic that settles them left them so.
void decisionMessage(const TruncationReport& t, std::vector<std::string>& out) {
    if (t.undecided == 0) return;
    out.push_back("snell: note: " + std::to_string(t.undecided) + " pixel(s) met a decision that rounding may have "
                  "flipped (which sphere is nearer, a hit or a miss, a shadow's edge, total internal reflection): "
                  "their bound covers both outcomes (--decision-mask shows where)");
}

}  // namespace

std::vector<std::string> truncationMessages(const TruncationReport& t, const TraceSettings& s) {
    std::vector<std::string> out;
    if (s.tolerance > 0.0) ladderMessages(t, s, out);
    else fixedTreeMessages(t, out);
    budgetMessage(t, s, out);
    decisionMessage(t, out);
    if (t.droppedGrowing > 0)
        out.push_back("snell: warning: " + std::to_string(t.droppedGrowing) + " pixel(s) dropped light trapped in a "
                      "material with ks + kt > 1, which may grow, for want of room to keep it for their next step: "
                      "their error is not estimated and the image is not certified there (--bound-image shows "
                      "where); the CPU reference (--cpu) keeps all of it" +
                      examples(t.droppedGrowingExamples, t.droppedGrowing));
    return out;
}

}  // namespace snell
