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
// Without branches, so that loops over pixels vectorise: 255 c + ½ >= ½ is
// positive, where truncation is floor.
inline std::uint8_t toByte(float c) {
    float clamped = c > 0.0f ? c : 0.0f;
    clamped = clamped < 1.0f ? clamped : 1.0f;
    return static_cast<std::uint8_t>(static_cast<int>(static_cast<double>(clamped) * 255.0 + 0.5));
}

}  // namespace snell
