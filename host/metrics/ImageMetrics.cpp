#include "metrics/ImageMetrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

namespace snell {

std::string ImageMetrics::json() const {
    char buffer[512];
    std::snprintf(buffer, sizeof buffer,
                  "{\"mean_abs_error\": %.6f, \"rmse\": %.6f, \"psnr\": %s, \"max_error\": %d, "
                  "\"bad_pixels\": %llu, \"bad_fraction\": %.8f, \"non_finite\": %llu, \"speckles\": %llu, "
                  "\"pixels\": %llu, \"estimated_pixels\": %llu, \"estimated_bad_pixels\": %llu, "
                  "\"uncertain_pixels\": %llu}",
                  meanAbsError, rmse, std::isfinite(psnr) ? std::to_string(psnr).c_str() : "null", maxError,
                  static_cast<unsigned long long>(badPixels), badFraction,
                  static_cast<unsigned long long>(nonFinite), static_cast<unsigned long long>(speckles),
                  static_cast<unsigned long long>(pixels), static_cast<unsigned long long>(estimated),
                  static_cast<unsigned long long>(estimatedBad), static_cast<unsigned long long>(uncertain));
    return buffer;
}

namespace {

void requireSameSize(int width, int height, const Image& b, const char* what) {
    if (width != b.width || height != b.height)
        throw std::invalid_argument(std::string(what) + " differ in size: " + std::to_string(width) + "x" +
                                    std::to_string(height) + " against " + std::to_string(b.width) + "x" +
                                    std::to_string(b.height));
}

// What the reference's bound image says of a pixel (compareImages).
enum class Standing { Certified, Estimated, Uncertain };
struct PixelStanding {
    Standing standing = Standing::Certified;
    int allowance = 0;  // 8-bit steps the reference may be off by, beyond the bad threshold
};
PixelStanding standing(float value) {
    // A NaN bound never certifies, nor proves anything wrong.
    if (std::isnan(value)) return {Standing::Uncertain, 255};
    const double steps = 255.0 * std::abs(double(value));
    const int allowance = steps <= 0.5 ? 0 : int(std::ceil(steps));
    if (isEstimate(value)) return {Standing::Estimated, allowance};
    return {allowance == 0 ? Standing::Certified : Standing::Uncertain, allowance};
}

// Pixel p's channel differences in 1/255 units: the largest, their sum and
// sum of squares, and the test pixel's NaN or infinite values.
struct PixelDifference {
    int worst = 0;
    double sum = 0.0, sumSquares = 0.0;
    int nonFinite = 0;
};

PixelDifference difference(const Image& test, const Image& reference, std::size_t p) {
    PixelDifference d;
    for (int k = 0; k < 3; ++k) {
        const float a = test.rgb[p * 3 + k];
        d.nonFinite += std::isfinite(a) ? 0 : 1;
        const int diff = std::abs(int(toByte(a)) - int(toByte(reference.rgb[p * 3 + k])));
        d.worst = std::max(d.worst, diff);
        d.sum += diff;
        d.sumSquares += double(diff) * diff;
    }
    return d;
}

// Off by more than 8/255 while all eight neighbours are within 2/255.
std::uint64_t countSpeckles(const std::vector<int>& worstOf, int width, int height) {
    std::uint64_t speckles = 0;
    for (int y = 1; y + 1 < height; ++y) {
        for (int x = 1; x + 1 < width; ++x) {
            if (worstOf[std::size_t(y) * width + x] <= 8) continue;
            bool isolated = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if ((dx || dy) && worstOf[std::size_t(y + dy) * width + (x + dx)] > 2) isolated = false;
            speckles += isolated;
        }
    }
    return speckles;
}

}  // namespace

ImageMetrics compareImages(const Image& test, const Image& reference, int badThreshold,
                           const BoundImage* referenceBound) {
    requireSameSize(test.width, test.height, reference, "images");
    if (referenceBound)
        requireSameSize(referenceBound->width, referenceBound->height, reference, "the bound image and the reference");
    ImageMetrics m;
    const std::size_t pixels = static_cast<std::size_t>(test.width) * test.height;
    std::vector<int> worstOf(pixels, 0);
    double sum = 0.0, sumSquares = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
        const PixelDifference d = difference(test, reference, p);
        m.nonFinite += d.nonFinite;
        const PixelStanding s = referenceBound ? standing(referenceBound->values[p]) : PixelStanding{};
        // No bound excuses a NaN pixel.
        const bool provenWrong = d.worst > s.allowance + badThreshold || d.nonFinite > 0;
        if (s.standing == Standing::Uncertain && !provenWrong) {
            ++m.uncertain;
            continue;
        }
        sum += d.sum;
        sumSquares += d.sumSquares;
        worstOf[p] = d.worst;
        m.maxError = std::max(m.maxError, d.worst);
        const bool bad = d.worst > badThreshold + (s.standing == Standing::Estimated ? s.allowance : 0);
        m.badPixels += bad;
        if (s.standing == Standing::Estimated) {
            ++m.estimated;
            m.estimatedBad += bad;
        }
    }
    m.pixels = pixels - m.uncertain;
    m.speckles = countSpeckles(worstOf, test.width, test.height);
    const double n = m.pixels ? 3.0 * m.pixels : 1.0;
    m.meanAbsError = sum / n;
    m.rmse = std::sqrt(sumSquares / n);
    // Nothing compared has no PSNR: never the perfect score of identical images.
    m.psnr = m.pixels == 0  ? std::numeric_limits<double>::quiet_NaN()
             : m.rmse > 0 ? 20.0 * std::log10(255.0 / m.rmse)
                          : std::numeric_limits<double>::infinity();
    m.badFraction = m.pixels ? double(m.badPixels) / m.pixels : 0.0;
    return m;
}

Image differenceImage(const Image& test, const Image& reference, int fullScale) {
    Image out(test.width, test.height);
    for (std::size_t p = 0; p < static_cast<std::size_t>(test.width) * test.height; ++p) {
        int worst = 0;
        bool bad = false;
        for (int k = 0; k < 3; ++k) {
            bad |= !std::isfinite(test.rgb[p * 3 + k]);
            worst = std::max(worst, std::abs(int(toByte(test.rgb[p * 3 + k])) - int(toByte(reference.rgb[p * 3 + k]))));
        }
        float* o = &out.rgb[p * 3];
        if (bad) { o[0] = 1; o[1] = 0; o[2] = 1; continue; }  // magenta: NaN/Inf
        if (worst == 0) continue;
        const float u = std::min(1.0f, float(worst) / fullScale);
        o[0] = u;
        o[1] = 0.25f * (1.0f - std::abs(2.0f * u - 1.0f));
        o[2] = 1.0f - u;
    }
    return out;
}

}  // namespace snell
