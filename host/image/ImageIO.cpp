#include "image/ImageIO.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include <unistd.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace snell {
namespace fs = std::filesystem;

namespace {

std::string extensionOf(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

std::vector<std::uint8_t> toBytes(const Image& image) {
    std::vector<std::uint8_t> bytes(image.rgb.size());
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = toByte(image.rgb[i]);
    return bytes;
}

std::string encode(const Image& image, ImageFormat format) {
    std::string out;
    switch (format) {
    case ImageFormat::Png: {
        const std::vector<std::uint8_t> bytes = toBytes(image);
        auto append = [](void* context, void* data, int size) {
            static_cast<std::string*>(context)->append(static_cast<const char*>(data), size);
        };
        if (!stbi_write_png_to_func(append, &out, image.width, image.height, 3, bytes.data(), image.width * 3))
            throw ImageIOError("PNG encoding failed");
        break;
    }
    case ImageFormat::Ppm: {
        out = "P6\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n255\n";
        const std::vector<std::uint8_t> bytes = toBytes(image);
        out.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
        break;
    }
    case ImageFormat::Pfm: {
        // PFM: rows bottom to top, negative scale = little-endian floats.
        out = "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
        const std::size_t row = static_cast<std::size_t>(image.width) * 3;
        for (int y = image.height - 1; y >= 0; --y)
            out.append(reinterpret_cast<const char*>(image.pixel(0, y)), row * sizeof(float));
        break;
    }
    }
    return out;
}

}  // namespace

ImageFormat formatForPath(const std::string& path) {
    const std::string ext = extensionOf(path);
    if (ext == ".png") return ImageFormat::Png;
    if (ext == ".ppm") return ImageFormat::Ppm;
    if (ext == ".pfm") return ImageFormat::Pfm;
    throw ImageIOError("cannot tell the image format of '" + path +
                       "': use the extension .png, .ppm or .pfm");
}

void checkWritable(const std::string& path) {
    formatForPath(path);
    fs::path p(path);
    if (fs::is_directory(p)) throw ImageIOError("output '" + path + "' is a directory");
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw ImageIOError("cannot write '" + path + "': directory '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
        throw ImageIOError("cannot write '" + path + "': directory '" + dir.string() +
                           "' is not writable (" + std::strerror(errno) + ")");
    if (fs::exists(p) && ::access(p.c_str(), W_OK) != 0)
        throw ImageIOError("cannot write '" + path + "': the file is not writable (" +
                           std::strerror(errno) + ")");
}

void writeImage(const std::string& path, const Image& image) {
    const std::string data = encode(image, formatForPath(path));
    // A unique temporary name in the same directory, so rename() is atomic.
    std::random_device random;
    const std::string temporary = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(random());
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) throw ImageIOError("cannot create '" + temporary + "': " + std::strerror(errno));
        out.write(data.data(), static_cast<std::streamsize>(data.size()));
        out.flush();
        if (!out) {
            const std::string reason = std::strerror(errno);
            out.close();
            std::remove(temporary.c_str());
            throw ImageIOError("cannot write '" + path + "': " + reason);
        }
    }
    if (std::rename(temporary.c_str(), path.c_str()) != 0) {
        const std::string reason = std::strerror(errno);
        std::remove(temporary.c_str());
        throw ImageIOError("cannot write '" + path + "': " + reason);
    }
}

Image readImage(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImageIOError("cannot open '" + path + "': " + std::strerror(errno));
    std::ostringstream buffer;
    buffer << in.rdbuf();
    const std::string data = buffer.str();
    const ImageFormat format = formatForPath(path);
    if (format == ImageFormat::Png) {
        int w, h, channels;
        unsigned char* pixels = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(data.data()),
                                                      static_cast<int>(data.size()), &w, &h, &channels, 3);
        if (!pixels) throw ImageIOError("cannot decode PNG '" + path + "': " + stbi_failure_reason());
        Image image(w, h);
        for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = pixels[i] / 255.0f;
        stbi_image_free(pixels);
        return image;
    }
    std::istringstream header(data);
    std::string magic;
    int w = 0, h = 0;
    double scale = 0;
    header >> magic >> w >> h >> scale;
    if (!header || w <= 0 || h <= 0 || (magic != "P6" && magic != "PF"))
        throw ImageIOError("'" + path + "' is not a P6 PPM or colour PFM file");
    const std::size_t offset = static_cast<std::size_t>(header.tellg()) + 1;
    Image image(w, h);
    if (magic == "P6") {
        if (scale != 255 || data.size() < offset + image.rgb.size())
            throw ImageIOError("'" + path + "': unsupported or truncated PPM");
        for (std::size_t i = 0; i < image.rgb.size(); ++i)
            image.rgb[i] = static_cast<unsigned char>(data[offset + i]) / 255.0f;
    } else {
        if (scale >= 0 || data.size() < offset + image.rgb.size() * sizeof(float))
            throw ImageIOError("'" + path + "': unsupported (big-endian) or truncated PFM");
        const std::size_t row = static_cast<std::size_t>(w) * 3;
        for (int y = 0; y < h; ++y)
            std::memcpy(image.pixel(0, h - 1 - y), data.data() + offset + y * row * sizeof(float), row * sizeof(float));
    }
    return image;
}

}  // namespace snell
