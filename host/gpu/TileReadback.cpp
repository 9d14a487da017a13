#include "gpu/TileReadback.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "common/Clock.h"

namespace snell::gpu {

namespace {

// The pixel's truncation, as the kernel reports it (shared_layout.h, OutputPixel).
PixelTruncation truncationOf(const OutputPixel& out, int imageX, int imageY) {
    PixelTruncation pixel;
    pixel.x = imageX;
    pixel.y = imageY;
    pixel.bound = std::abs(out.colour.a);  // negative where not finite
    pixel.unbounded = out.colour.a < 0.0f;
    pixel.overBudget = (out.report & SNELL_PIXEL_OVER_BUDGET) != 0;
    pixel.overTolerance = (out.report & (SNELL_PIXEL_OVER_TOLERANCE | SNELL_PIXEL_DROPPED_GROWING)) != 0;
    pixel.estimated = out.estimate >= 0.0f;
    if (pixel.estimated) pixel.estimatedError = out.estimate;  // the kernel reports no other estimate
    pixel.droppedGrowing = (out.report & SNELL_PIXEL_DROPPED_GROWING) != 0;
    return pixel;
}

// Float's unit roundoff: the kernel's colours are float in either precision.
constexpr double kFloatRoundoff = 0x1p-24;

// The rays the pixel's trees traced (OutputPixel::report).
std::uint32_t raysOf(const OutputPixel& out) { return out.report >> SNELL_PIXEL_RAYS_SHIFT; }

// The relative rounding of the kernel's float colour arithmetic: a sum of n
// terms >= 0 is within (n − 1)·u of its own value (Higham, "Accuracy and
// Stability of Numerical Algorithms", §4.2); a pixel's terms are its rays'
// (each with its lights), and each weight is a product of at most that many
// factors.
double sumRounding(const OutputPixel& out, std::size_t lights) {
    return (double(raysOf(out)) + 4.0) * (double(lights) + 1.0) * kFloatRoundoff;
}
// What it may have rounded away of the clamped colour and its bound.
double colourRounding(const OutputPixel& out, const PixelTruncation& pixel, std::size_t lights) {
    const double colour = std::max({out.colour.r, out.colour.g, out.colour.b, 0.0f});
    return sumRounding(out, lights) * (std::min(colour, 1.0) + pixel.bound);
}

// What the pixel's float sum may hold beyond the exact one's (whiteEitherWay):
// what the kernel reports (OutputPixel::excess) and the sum's own rounding at
// its value.
double excessOf(const OutputPixel& out, std::size_t lights) {
    const double colour = std::max({out.colour.r, out.colour.g, out.colour.b, 0.0f});
    return double(out.excess) + sumRounding(out, lights) * colour;
}

// Above this, what a pixel's float decisions and shading may have got wrong
// is re-traced (where the request can) rather than stated in its bound: the
// tolerance, and at most half an 8-bit step.
double retraceAbove(const RenderRequest& request) {
    const double step = 0.5 / 255.0;
    return request.trace.tolerance > 0.0 ? std::min(step, request.trace.tolerance) : step;
}

// The pixel marked undecided, and what its undecided decisions may have moved
// (OutputPixel::moved) covered. Where the kernel found that movement bounded
// (R finite in every channel its undecided rays weigh) the bound is widened;
// else `moved` was a guess, and a pixel that states an estimate keeps it,
// grown by the guess, while that is within `small`; past it, the pixel has no
// bound but the clamp, and no estimate (render/Truncation.h:
// TruncationReport::undecidedUnbounded). The caller adds `moved` to the bound.
void widen(PixelTruncation& pixel, const OutputPixel& out, double small) {
    pixel.undecided = true;
    if ((out.report & SNELL_PIXEL_MOVED_UNBOUNDED) == 0) return;
    if (pixel.estimated && out.moved <= small) {
        pixel.estimatedError += out.moved;
        return;
    }
    pixel.bound = std::max(pixel.bound, clampOnlyBound(glm::dvec3(out.colour.r, out.colour.g, out.colour.b)));
    pixel.unbounded = true;
    pixel.estimated = false;
    pixel.estimatedError = std::numeric_limits<double>::infinity();
}

// A supersampled pixel's flagged samples (shared_layout.h, FlaggedSamples):
// where given, they hold all its undecided light, and each other sample's
// shading rounding is within what a pixel keeps unless re-traced
// (steps.glsl, closeSample). Then only they are traced again (0: the whole
// pixel), where its truncation bound is the same before the clamp: no
// channel reaches 1 within it.
std::uint64_t samplesToRetrace(const OutputPixel& out, const FlaggedSamples* flagged, int samples) {
    if (!flagged) return 0;
    const std::uint64_t mask = std::uint64_t(flagged->low) | std::uint64_t(flagged->high) << 32;
    if (mask == 0 || std::popcount(mask) >= samples || !(out.colour.a >= 0.0f)) return 0;
    const double colour = std::max({out.colour.r, out.colour.g, out.colour.b});
    return colour + out.colour.a < 1.0 ? mask : 0;
}

// A pixel whose flagged samples the CPU reference traced again: its other
// samples' light as the kernel summed it, and theirs. The exact colour lies
// below that by at most what rounding may have moved (the others' shading,
// the float sums, the reference's widening), above it also by the
// truncation of both; its bound is that interval's width after SPEC §6's
// clamp, in its widest channel.
void combineSamples(RetracedPixel& p, const OutputPixel& out, const FlaggedSamples& flagged, int samples,
                    std::size_t lights) {
    const double share = double(std::popcount(p.samples)) / samples;
    const double colour = std::max({out.colour.r, out.colour.g, out.colour.b, 0.0f});
    const double shading = double(flagged.light.a) / samples * (1.0 + 0x1p-20);
    const double below = shading + 2.0 * sumRounding(out, lights) * colour + share * p.widening;
    const double above = below + double(out.colour.a) + share * p.gap;
    const float light[3] = {flagged.light.r, flagged.light.g, flagged.light.b};
    const float kernel[3] = {out.colour.r, out.colour.g, out.colour.b};
    double bound = 0.0;
    for (int c = 0; c < 3; ++c) {
        p.colour[c] = kernel[c] - double(light[c]) / samples + share * p.colour[c];
        bound = std::max(bound, std::clamp(p.colour[c] + above, 0.0, 1.0) - std::clamp(p.colour[c] - below, 0.0, 1.0));
    }
    p.truncation.bound = bound;
    p.truncation.overBudget = p.truncation.overBudget || (out.report & SNELL_PIXEL_OVER_BUDGET) != 0;
    p.truncation.overTolerance =
        p.truncation.overTolerance || (out.report & (SNELL_PIXEL_OVER_TOLERANCE | SNELL_PIXEL_DROPPED_GROWING)) != 0;
}

// Pixels whose trees traced more rays than this are not handed to the CPU
// reference, whose time a ray is several of the kernel's: their bound is
// widened instead (docs/decisions.md). Nor are pixels that state
// an estimate, not a bound: the reference would only estimate them again.
constexpr std::uint32_t kRetraceRays = 1024;

}  // namespace

void readBackTile(const OutputPixel* pixels, const FlaggedSamples* flagged, const RenderRequest& request, const TilePlan& plan,
                  const TileParams& tile, const SceneFacts& facts, Image& rows, int firstRow, RenderProgress& progress,
                  GpuRenderResult& result) {
    const auto readStart = Clock::now();
    const PixelWindow& area = plan.area;
    TruncationReport& truncation = progress.truncation;
    const int samples = request.samplesTraced();
    std::vector<RetracedPixel> retraced;
    std::vector<std::size_t> retracedFrom;  // their index in the tile
    for (std::uint32_t y = 0; y < tile.height; ++y) {
        const int imageY = imageRow(tile, y), windowRow = imageY - area.y0;
        float* row = rows.pixel(0, windowRow - firstRow);
        const OutputPixel* src = pixels + std::size_t(y) * tile.width;
        for (std::uint32_t x = 0; x < tile.width; ++x) {
            const OutputPixel& out = src[x];
            const int imageX = imageColumn(tile, x), column = imageX - area.x0;
            row[column * 3 + 0] = out.colour.r;
            row[column * 3 + 1] = out.colour.g;
            row[column * 3 + 2] = out.colour.b;
            PixelTruncation pixel = truncationOf(out, imageX, imageY);
            if (request.rayImage)
                (*request.rayImage)[std::size_t(windowRow) * area.width() + column] = float(raysOf(out));
            // What the float decisions and shading may have got wrong: past
            // what a bound should take, the pixel is traced again in double.
            const bool undecided = (out.report & SNELL_PIXEL_UNDECIDED) != 0;
            const double moved = out.moved;
            // A pixel white whichever way its decisions went needs neither.
            if ((undecided || moved > 0.0) &&
                whiteEitherWay(glm::dvec3(out.colour.r, out.colour.g, out.colour.b), excessOf(out, facts.lights))) {
                truncation.add(pixel);
                request.recordTruncation(std::size_t(windowRow) * area.width() + column, pixel);
                continue;
            }
            if ((undecided || moved > 0.0) && request.retrace && !(moved <= retraceAbove(request)) &&
                !pixel.unbounded && raysOf(out) <= kRetraceRays) {
                const std::size_t at = std::size_t(y) * tile.width + x;
                RetracedPixel again;
                again.x = imageX;
                again.y = imageY;
                again.samples = samplesToRetrace(out, flagged ? flagged + at : nullptr, samples);
                retraced.push_back(again);
                retracedFrom.push_back(at);
                continue;
            }
            if (undecided) widen(pixel, out, retraceAbove(request));
            pixel.bound = std::min(1.0, pixel.bound + moved + colourRounding(out, pixel, facts.lights));
            truncation.add(pixel);
            request.recordTruncation(std::size_t(windowRow) * area.width() + column, pixel);
        }
    }
    // The pixels handed to the CPU reference, as it traced them.
    if (!retraced.empty()) {
        request.retrace(retraced);
        // Flagged samples whose light the reference could not bound (R
        // infinite in reach): their pixels are traced again whole, which may
        // state an estimate instead.
        std::vector<RetracedPixel> whole;
        std::vector<std::size_t> wholeAt;
        for (std::size_t i = 0; i < retraced.size(); ++i) {
            RetracedPixel& p = retraced[i];
            if (p.samples != 0 && !(std::isfinite(p.widening) && std::isfinite(p.gap))) {
                p.samples = 0;
                whole.push_back(p);
                wholeAt.push_back(i);
            }
        }
        if (!whole.empty()) {
            request.retrace(whole);
            for (std::size_t j = 0; j < whole.size(); ++j) retraced[wholeAt[j]] = whole[j];
        }
        for (std::size_t i = 0; i < retraced.size(); ++i) {
            RetracedPixel& p = retraced[i];
            if (p.samples != 0)
                combineSamples(p, pixels[retracedFrom[i]], flagged[retracedFrom[i]], samples, facts.lights);
            const int windowRow = p.y - area.y0, column = p.x - area.x0;
            float* row = rows.pixel(column, windowRow - firstRow);
            for (int k = 0; k < 3; ++k) row[k] = static_cast<float>(p.colour[k]);
            p.truncation.retraced = true;
            p.truncation.retracedSamples = p.samples != 0 ? std::popcount(p.samples) : samples;
            truncation.add(p.truncation);
            request.recordTruncation(std::size_t(windowRow) * area.width() + column, p.truncation);
        }
    }
    result.readbackMs += msSince(readStart);
    ++result.tiles;
    ++progress.tilesDone;
}

}  // namespace snell::gpu
