#include "gpu/TileReadback.h"

#include <algorithm>
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
    pixel.overBudget = out.truncation.y != 0.0f;
    pixel.overTolerance = out.truncation.z != 0.0f;
    pixel.estimated = out.truncation.x >= 0.0f;
    if (pixel.estimated) pixel.estimatedError = out.truncation.x;  // the kernel reports no other estimate
    pixel.droppedGrowing = out.truncation.z == 2.0f;
    return pixel;
}

// Float's unit roundoff: the kernel's colours are float in either precision.
constexpr double kFloatRoundoff = 0x1p-24;

// The relative rounding of the kernel's float colour arithmetic: a sum of n
// terms >= 0 is within (n − 1)·u of its own value (Higham, "Accuracy and
// Stability of Numerical Algorithms", §4.2); a pixel's terms are its rays'
// (each with its lights), and each weight is a product of at most that many
// factors.
double sumRounding(const OutputPixel& out, std::size_t lights) {
    return (double(out.truncation.w) + 4.0) * (double(lights) + 1.0) * kFloatRoundoff;
}
// What it may have rounded away of the clamped colour and its bound.
double colourRounding(const OutputPixel& out, const PixelTruncation& pixel, std::size_t lights) {
    const double colour = std::max({out.colour.r, out.colour.g, out.colour.b, 0.0f});
    return sumRounding(out, lights) * (std::min(colour, 1.0) + pixel.bound);
}

// What the pixel's float sum may hold beyond the exact one's (whiteEitherWay):
// light the exact tree may not hold (covered rays', undecided shadow rays'),
// shading's rounding (`shading`, per sample) and the sum's own at its value.
double excessOf(const OutputPixel& out, double shading, int samples, std::size_t lights) {
    const double colour = std::max({out.colour.r, out.colour.g, out.colour.b, 0.0f});
    return double(out.shading.y) / samples + shading + sumRounding(out, lights) * colour;
}

// Above this, what a pixel's float decisions and shading may have got wrong
// is re-traced (where the request can) rather than stated in its bound: the
// tolerance, and at most half an 8-bit step.
double retraceAbove(const RenderRequest& request) {
    const double step = 0.5 / 255.0;
    return request.trace.tolerance > 0.0 ? std::min(step, request.trace.tolerance) : step;
}

// What a pixel's undecided decisions (physics/margins.glsl) may change of its
// colour, either way: its rays' weight times R, and its shadow rays' light.
// Where R is infinite in a channel of that weight there is no bound, and
// `guess` is the estimate, the weight times the most light one hit returns
// (as for light not traced: render/Truncation.h, ErrorEstimate).
struct Undecided {
    double widening = 0.0;
    double guess = 0.0;
    bool bounded = true;
};
Undecided undecidedOf(const OutputPixel& out, const RadianceBound& radiance, int samples) {
    Undecided u;
    const float weight[3] = {out.undecided.r, out.undecided.g, out.undecided.b};
    double widening = 0.0, guess = 0.0;
    for (int c = 0; c < 3; ++c) {
        if (!(weight[c] > 0.0f)) continue;
        if (std::isfinite(radiance.radiance[c])) widening = std::max(widening, weight[c] * radiance.radiance[c]);
        else u.bounded = false;
        guess = std::max(guess, weight[c] * radiance.local[c]);
    }
    u.widening = (widening + out.undecided.a) / samples;
    u.guess = (std::max(widening, guess) + out.undecided.a) / samples;
    return u;
}

// The pixel's bound widened to cover both outcomes, where there is one. Else
// a pixel that states an estimate keeps it, grown by the guess, while that is
// within `small`; past it, the pixel has no bound but the clamp, and no
// estimate (render/Truncation.h: TruncationReport::undecidedUnbounded).
void widen(PixelTruncation& pixel, const OutputPixel& out, const Undecided& u, double small) {
    pixel.undecided = true;
    if (u.bounded) {
        pixel.bound = std::min(1.0, pixel.bound + u.widening);
        return;
    }
    if (pixel.estimated && u.guess <= small) {
        pixel.estimatedError += u.guess;
        return;
    }
    pixel.bound = std::max(pixel.bound, clampOnlyBound(glm::dvec3(out.colour.r, out.colour.g, out.colour.b)));
    pixel.unbounded = true;
    pixel.estimated = false;
    pixel.estimatedError = std::numeric_limits<double>::infinity();
}

// Pixels whose trees traced more rays than this are not handed to the CPU
// reference, whose time a ray is several of the kernel's: their bound is
// widened instead (docs/accuracy.md, "Decisions"). Nor are pixels that state
// an estimate, not a bound: the reference would only estimate them again.
constexpr float kRetraceRays = 1024.0f;

}  // namespace

void readBackTile(const OutputPixel* pixels, const RenderRequest& request, const TilePlan& plan,
                  const TileParams& tile, const SceneFacts& facts, Image& rows, int firstRow, RenderProgress& progress,
                  GpuRenderResult& result) {
    const auto readStart = Clock::now();
    const PixelWindow& area = plan.area;
    TruncationReport& truncation = progress.truncation;
    const int samples = request.samplesTraced();
    std::vector<RetracedPixel> retraced;
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
                (*request.rayImage)[std::size_t(windowRow) * area.width() + column] = out.truncation.w;
            // What the float decisions and shading may have got wrong: past
            // what a bound should take, the pixel is traced again in double.
            const Undecided undecided = undecidedOf(out, facts.radiance, samples);
            const bool any = out.undecided.r > 0.0f || out.undecided.g > 0.0f || out.undecided.b > 0.0f ||
                             out.undecided.a > 0.0f;
            const double shading = out.shading.x / double(samples);
            // A pixel white whichever way its decisions went needs neither.
            if ((any || shading > 0.0) &&
                whiteEitherWay(glm::dvec3(out.colour.r, out.colour.g, out.colour.b),
                               excessOf(out, shading, samples, facts.lights))) {
                truncation.add(pixel);
                request.recordTruncation(std::size_t(windowRow) * area.width() + column, pixel);
                continue;
            }
            const double moved = (undecided.bounded ? undecided.widening : undecided.guess) + shading;
            if ((any || shading > 0.0) && request.retrace && !(moved <= retraceAbove(request)) &&
                !pixel.unbounded && out.truncation.w <= kRetraceRays) {
                RetracedPixel again;
                again.x = imageX;
                again.y = imageY;
                retraced.push_back(again);
                continue;
            }
            if (any) widen(pixel, out, undecided, retraceAbove(request));
            pixel.bound = std::min(1.0, pixel.bound + shading + colourRounding(out, pixel, facts.lights));
            truncation.add(pixel);
            request.recordTruncation(std::size_t(windowRow) * area.width() + column, pixel);
        }
    }
    // The pixels handed to the CPU reference, as it traced them.
    if (!retraced.empty()) {
        request.retrace(retraced);
        for (RetracedPixel& p : retraced) {
            const int windowRow = p.y - area.y0, column = p.x - area.x0;
            float* row = rows.pixel(column, windowRow - firstRow);
            for (int k = 0; k < 3; ++k) row[k] = static_cast<float>(p.colour[k]);
            p.truncation.retraced = true;
            truncation.add(p.truncation);
            request.recordTruncation(std::size_t(windowRow) * area.width() + column, p.truncation);
        }
    }
    result.readbackMs += msSince(readStart);
    ++result.tiles;
    ++progress.tilesDone;
}

}  // namespace snell::gpu
