// A render's truncation bound as a file (render --bound-image) and as compare
// reads it back. Each pixel holds one number: its bound, how far at most it is
// from the exact image (SPEC §4), certified; or, where it has no finite bound
// (light of a material with ks + kt >= 1, which only the clamp bounds) and its
// error was estimated (render/Truncation.h, ErrorEstimate), minus that
// estimate: the sign marks a value that is not a bound. PFM and EXR files are
// grey (one channel: "Pf", "Y") and exact; EXR and PNG carry the marker text
// below. PNG and PPM hold the magnitudes in 8 bits, for the eye only.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "image/ImageIO.h"

namespace snell {

// The text (key, value) that marks a bound image.
inline constexpr const char* kBoundImageKey = "Content";
inline constexpr const char* kBoundImageContent = "snell truncation bound";

struct BoundImage {
    int width = 0, height = 0;
    std::vector<float> values;  // row-major, as above
    std::string note;           // how an unmarked file was taken for one (an earlier snell's)
};

// Whether a value is an estimate rather than a bound (NaN is neither).
inline bool isEstimate(float value) { return std::signbit(value) && !std::isnan(value); }
// A pixel's value from its bound and its estimate (+inf: none made).
inline float boundImageValue(float bound, float estimate) { return std::isfinite(estimate) ? -estimate : bound; }

// `bounds` and `estimates` row-major, width × height (estimates may be empty).
void writeBoundImage(const std::string& path, int width, int height, const std::vector<float>& bounds,
                     const std::vector<float>& estimates, const ImagePlacement& placement,
                     ExrCompression compression);

// Throws ImageIOError, naming the file, where it is not a float bound image:
// an 8-bit file, a colour image (a render), a grey image that is not marked.
// An unmarked RGB file of equal channels that names no scene, as earlier
// versions wrote them, is read with a note.
BoundImage readBoundImage(const std::string& path);

}  // namespace snell
