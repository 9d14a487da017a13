// Image files: PNG (8-bit), PPM P6 (8-bit) and PFM (float, unclamped), chosen
// by extension. Writes are atomic: a temporary file beside the target, renamed
// over it only when complete, so a failed or interrupted write never leaves a
// partial or clobbered file.
#pragma once

#include <stdexcept>
#include <string>

#include "image/Image.h"

namespace snell {

class ImageIOError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class ImageFormat { Png, Ppm, Pfm };

// The format for a path's extension; throws ImageIOError for anything else.
ImageFormat formatForPath(const std::string& path);

// Check, before any rendering, that `path` can be written: known extension and
// a writable directory. Throws ImageIOError with the reason.
void checkWritable(const std::string& path);

void writeImage(const std::string& path, const Image& image);
Image readImage(const std::string& path);

}  // namespace snell
