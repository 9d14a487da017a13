// Image files: PNG (8-bit), PPM P6 (8-bit), PFM and OpenEXR (float,
// unclamped; EXR through tinyexr, 32-bit float, ZIP), chosen by extension.
// EXR is the one format written whole at the end: its memory is 12 bytes a
// pixel. Writing streams rows (an image of any size is written with
// bounded memory) into a temporary file beside the target, renamed over it
// only on commit(), so a failed or interrupted write never leaves a partial or
// clobbered file.
#pragma once

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "image/Image.h"

namespace snell {

class ImageIOError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class ImageFormat { Png, Ppm, Pfm, Exr };

// "-" as a path: standard output, as PPM (for pipes). Rows stream out as they
// finish; a failed render there ends the stream early (and the exit status
// says so), since a pipe cannot be taken back.
inline const std::string kStandardOutput = "-";

// The format for a path's extension; throws ImageIOError for anything else.
ImageFormat formatForPath(const std::string& path);

// Check, before any rendering, that `path` can be written: known extension and
// a writable directory. Throws ImageIOError with the reason.
void checkWritable(const std::string& path);

// Text stored with the image where the format allows (PNG tEXt chunks).
using ImageText = std::vector<std::pair<std::string, std::string>>;

// Rows of width × 3 floats, top to bottom, in one or more calls.
class ImageWriter {
public:
    // Opens a temporary file beside `path`. Throws ImageIOError.
    static std::unique_ptr<ImageWriter> open(const std::string& path, int width, int height,
                                             const ImageText& text = {});
    virtual ~ImageWriter();
    // The next `rows` rows (rgb floats, width * 3 per row).
    virtual void writeRows(const float* rgb, int rows) = 0;
    // All rows written: finish the file and rename it over the target.
    void commit();

protected:
    ImageWriter(std::string path, int width, int height);
    virtual void finish() = 0;
    std::string path_, temporary_;
    std::FILE* file_ = nullptr;
    int width_, height_;
    int rowsWritten_ = 0;
    bool committed_ = false;
};

void writeImage(const std::string& path, const Image& image, const ImageText& text = {});
Image readImage(const std::string& path);

}  // namespace snell
