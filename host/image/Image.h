// A float RGB image, rows top to bottom: what every renderer produces and every
// writer, reader and metric consumes.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

namespace snell {

struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;  // width * height * 3, unclamped

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3, 0.0f) {}
    float* pixel(int x, int y) { return &rgb[(static_cast<std::size_t>(y) * width + x) * 3]; }
    const float* pixel(int x, int y) const { return &rgb[(static_cast<std::size_t>(y) * width + x) * 3]; }
};

// SPEC §6: clamp to [0, 1], then round(255 c) with halves rounded up.
// NaN maps to 0 here; metrics count NaN separately.
inline std::uint8_t toByte(float c) {
    if (!(c > 0.0f)) return 0;
    if (c >= 1.0f) return 255;
    return static_cast<std::uint8_t>(std::floor(static_cast<double>(c) * 255.0 + 0.5));
}

}  // namespace snell
