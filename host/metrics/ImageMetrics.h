// Error metrics between a test image and a reference, in 8-bit units after the
// SPEC §6 clamp and rounding: what "agrees with the exact image" means.
#pragma once

#include <cstdint>
#include <string>

#include "image/BoundImage.h"
#include "image/Image.h"

namespace snell {

struct ImageMetrics {
    double meanAbsError = 0.0;    // mean |a − b| over all channels, in 1/255 units
    double rmse = 0.0;            // in 1/255 units
    double psnr = 0.0;            // dB, 8-bit peak; +inf when identical, NaN when no pixel was compared
    int maxError = 0;             // largest channel difference, in 1/255 units
    std::uint64_t badPixels = 0;  // pixels with some channel off by > badThreshold
    double badFraction = 0.0;
    std::uint64_t nonFinite = 0;  // NaN or Inf values in the test image
    // Isolated errors: off by more than 8/255 while all eight neighbours are
    // within 2/255 (acne and self-intersection show up as these).
    std::uint64_t speckles = 0;
    std::uint64_t pixels = 0;     // pixels compared (uncertain ones left out)
    std::uint64_t estimated = 0;  // of those, held to the reference's estimated error (no bound)
    std::uint64_t estimatedBad = 0;  // of those, bad
    std::uint64_t uncertain = 0;  // left out: the reference's bound cannot decide them
    std::string json() const;
};

// Compare `test` against `reference` (same size, else std::invalid_argument).
// With `referenceBound` (render --bound-image of the reference: how far each
// reference pixel may be from the exact image, image/BoundImage.h):
// * a pixel the reference certifies in 8 bits (bound at most half a step,
//   SPEC §6) is compared as without it;
// * a pixel whose value is an estimated error e (it has no finite bound) is
//   held to it: compared, counted as estimated, and bad where the test is off
//   by more than the bad threshold plus e (rounded up to 8-bit steps, none
//   within half a step);
// * any other pixel (a bound over half a step) is left out and counted as
//   uncertain, unless the test is off by more than the bound allows plus the
//   bad threshold: the bound proves that one wrong.
ImageMetrics compareImages(const Image& test, const Image& reference, int badThreshold = 3,
                           const BoundImage* referenceBound = nullptr);

// A false-colour difference image: black where equal, blue → red as the
// largest channel difference grows to `fullScale`/255.
Image differenceImage(const Image& test, const Image& reference, int fullScale = 16);

}  // namespace snell
