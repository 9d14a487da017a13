// Image files: PNG (8-bit), PPM P6 (8-bit), PFM and OpenEXR (float,
// unclamped; EXR through the OpenEXR library, 32-bit float, lossless), chosen by
// extension. Writing streams rows (an image of any size is written with
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

// Text stored with the image where the format allows (PNG tEXt chunks, EXR
// string attributes).
using ImageText = std::vector<std::pair<std::string, std::string>>;

// Where an image lies within a larger one (a piece rendered with --region):
// its top-left pixel there and the larger image's size (0: the image's own).
// EXR keeps it as its data and display windows; the other formats do not.
struct ImagePlacement {
    int x = 0, y = 0;
    int fullWidth = 0, fullHeight = 0;
    bool stored = false;  // read from the file (EXR)
};

// How EXR scan lines are compressed; every choice is lossless. Measured on
// 8192² renders (docs/log/writing-images.md, "Writing images"): PIZ is the fastest
// that compresses a detailed render (RLE leaves one whole; ZIP takes 1.7x as
// long for a file 5 % smaller); RLE is 2x faster on flat images, none faster
// still where the disk is fast.
enum class ExrCompression { None, Rle, Zip, Piz };
inline constexpr ExrCompression kExrCompressions[] = {ExrCompression::Piz, ExrCompression::Rle, ExrCompression::Zip,
                                                      ExrCompression::None};
inline constexpr ExrCompression kDefaultExrCompression = ExrCompression::Piz;
// "none", "rle", "zip", "piz"
const char* exrCompressionName(ExrCompression compression);
// The compression named `name`; throws ImageIOError for an unknown name.
ExrCompression exrCompressionNamed(const std::string& name);

// The channels a float file holds: RGB, or one grey channel (a PFM "Pf", an
// EXR of "Y" alone), for a quantity per pixel rather than a colour (the
// truncation bound). Rows are given as RGB either way, and a grey file keeps
// their first channel; PNG and PPM write grey as RGB.
enum class ImageLayout { Rgb, Grey };

// What a file says of its image beside its pixels.
struct ImageHeader {
    ImagePlacement placement;
    ImageText text;     // PNG tEXt chunks, EXR string attributes
    int channels = 3;   // 1: a grey file (ImageLayout::Grey), read as R = G = B
};

// Rows of width × 3 floats, top to bottom, in one or more calls.
class ImageWriter {
public:
    // Opens a temporary file beside `path`. Throws ImageIOError.
    static std::unique_ptr<ImageWriter> open(const std::string& path, int width, int height,
                                             const ImageText& text = {}, const ImagePlacement& placement = {},
                                             ExrCompression compression = kDefaultExrCompression,
                                             ImageLayout layout = ImageLayout::Rgb);
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

void writeImage(const std::string& path, const Image& image, const ImageText& text = {},
                const ImagePlacement& placement = {}, ExrCompression compression = kDefaultExrCompression,
                ImageLayout layout = ImageLayout::Rgb);
// `placement`, if given, receives where the file says the image lies.
Image readImage(const std::string& path, ImagePlacement* placement = nullptr);
// `header` receives all the file says of the image.
Image readImage(const std::string& path, ImageHeader* header);

}  // namespace snell
