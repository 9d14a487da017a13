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
                  "\"pixels\": %llu}",
                  meanAbsError, rmse, std::isfinite(psnr) ? std::to_string(psnr).c_str() : "null", maxError,
                  static_cast<unsigned long long>(badPixels), badFraction,
                  static_cast<unsigned long long>(nonFinite), static_cast<unsigned long long>(speckles),
                  static_cast<unsigned long long>(pixels));
    return buffer;
}

ImageMetrics compareImages(const Image& test, const Image& reference, int badThreshold) {
    if (test.width != reference.width || test.height != reference.height)
        throw std::invalid_argument("images differ in size: " + std::to_string(test.width) + "x" +
                                    std::to_string(test.height) + " against " +
                                    std::to_string(reference.width) + "x" + std::to_string(reference.height));
    ImageMetrics m;
    m.pixels = static_cast<std::uint64_t>(test.width) * test.height;
    std::vector<int> worstOf(m.pixels, 0);
    double sum = 0.0, sumSquares = 0.0;
    for (std::size_t p = 0; p < m.pixels; ++p) {
        int worst = 0;
        for (int k = 0; k < 3; ++k) {
            const float a = test.rgb[p * 3 + k];
            if (!std::isfinite(a)) ++m.nonFinite;
            const int diff = std::abs(int(toByte(a)) - int(toByte(reference.rgb[p * 3 + k])));
            sum += diff;
            sumSquares += double(diff) * diff;
            worst = std::max(worst, diff);
        }
        worstOf[p] = worst;
        m.maxError = std::max(m.maxError, worst);
        if (worst > badThreshold) ++m.badPixels;
    }
    for (int y = 1; y + 1 < test.height; ++y) {
        for (int x = 1; x + 1 < test.width; ++x) {
            if (worstOf[std::size_t(y) * test.width + x] <= 8) continue;
            bool isolated = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if ((dx || dy) && worstOf[std::size_t(y + dy) * test.width + (x + dx)] > 2) isolated = false;
            m.speckles += isolated;
        }
    }
    const double n = m.pixels ? 3.0 * m.pixels : 1.0;
    m.meanAbsError = sum / n;
    m.rmse = std::sqrt(sumSquares / n);
    m.psnr = m.rmse > 0 ? 20.0 * std::log10(255.0 / m.rmse) : std::numeric_limits<double>::infinity();
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
