#include "image/BoundImage.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace snell {
namespace {

std::string textOf(const ImageText& text, const std::string& key) {
    for (const auto& [k, v] : text)
        if (k == key) return v;
    return {};
}

bool marked(const ImageHeader& header) { return textOf(header.text, kBoundImageKey) == kBoundImageContent; }

bool greyEverywhere(const Image& image) {
    for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
        const float r = image.rgb[i], g = image.rgb[i + 1], b = image.rgb[i + 2];
        // Bitwise, so that NaN, -0 and the rest compare as written.
        if (std::memcmp(&r, &g, sizeof r) != 0 || std::memcmp(&r, &b, sizeof r) != 0) return false;
    }
    return true;
}

constexpr const char* kHowToWrite = "render the reference with --bound-image B.pfm or B.exr";

}  // namespace

void writeBoundImage(const std::string& path, int width, int height, const std::vector<float>& bounds,
                     const std::vector<float>& estimates, const ImagePlacement& placement,
                     ExrCompression compression) {
    const ImageFormat format = formatForPath(path);
    const bool exact = format == ImageFormat::Pfm || format == ImageFormat::Exr;
    Image image(width, height);
    for (std::size_t i = 0; i < bounds.size(); ++i) {
        const float v = boundImageValue(bounds[i], estimates.empty() ? std::numeric_limits<float>::infinity() : estimates[i]);
        // An 8-bit picture shows how far, whichever it is.
        image.rgb[3 * i] = image.rgb[3 * i + 1] = image.rgb[3 * i + 2] = exact ? v : std::abs(v);
    }
    const ImageText text{{kBoundImageKey, kBoundImageContent},
                         {"Comment", "each pixel: how far it may be from the exact image, a certified bound (>= 0); "
                                     "where it has no finite bound and its error was estimated, minus the estimate"}};
    writeImage(path, image, text, placement, compression, ImageLayout::Grey);
}

BoundImage readBoundImage(const std::string& path) {
    const ImageFormat format = formatForPath(path);
    ImageHeader header;
    if (format == ImageFormat::Png || format == ImageFormat::Ppm) {
        readImage(path, &header);
        throw ImageIOError("'" + path + "' is an 8-bit image" +
                           (marked(header) ? std::string(" (a bound image for the eye)") : std::string()) +
                           ": a bound image for compare is a float file (.pfm or .exr): " + kHowToWrite);
    }
    const Image image = readImage(path, &header);
    BoundImage bound{image.width, image.height, {}, {}};
    const bool pfmGrey = format == ImageFormat::Pfm && header.channels == 1;
    if (!marked(header) && !pfmGrey) {
        const std::string scene = textOf(header.text, "Source");
        if (!scene.empty())
            throw ImageIOError("'" + path + "' is a render of '" + scene + "', not a bound image: " + kHowToWrite);
        if (header.channels == 1)
            throw ImageIOError("'" + path + "' is a grey image without snell's bound-image marker (text '" +
                               kBoundImageKey + "'), not a bound image: " + kHowToWrite);
        if (!greyEverywhere(image))
            throw ImageIOError("'" + path + "' is a colour image (its channels differ), not a bound image: " +
                               kHowToWrite);
        bound.note = "'" + path + "' has no bound-image marker; read as an earlier snell's bound image, as its three "
                     "channels are equal everywhere (such a file marks no estimates)";
    }
    bound.values.resize(std::size_t(image.width) * image.height);
    for (std::size_t i = 0; i < bound.values.size(); ++i) bound.values[i] = image.rgb[3 * i];
    return bound;
}

}  // namespace snell
