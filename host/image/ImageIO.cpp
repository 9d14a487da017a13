#include "image/ImageIO.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

#include <mutex>
#include <thread>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <png.h>
#include <zlib.h>
#include <unistd.h>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>

#include "image/PngText.h"

namespace snell {
namespace fs = std::filesystem;

namespace {

std::string extensionOf(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

std::string errorText() { return std::strerror(errno); }

// PPM P6: header, then 8-bit rows top to bottom.
class PpmWriter : public ImageWriter {
public:
    PpmWriter(std::string path, int width, int height) : ImageWriter(std::move(path), width, height) {
        const std::string header = "P6\n" + std::to_string(width) + " " + std::to_string(height) + "\n255\n";
        if (std::fwrite(header.data(), 1, header.size(), file_) != header.size())
            throw ImageIOError("cannot write '" + path_ + "': " + errorText());
        row_.resize(std::size_t(width) * 3);
    }
    void writeRows(const float* rgb, int rows) override {
        for (int r = 0; r < rows; ++r, rgb += std::size_t(width_) * 3) {
            for (std::size_t i = 0; i < row_.size(); ++i) row_[i] = toByte(rgb[i]);
            if (std::fwrite(row_.data(), 1, row_.size(), file_) != row_.size())
                throw ImageIOError("cannot write '" + path_ + "': " + errorText());
        }
        rowsWritten_ += rows;
    }

private:
    void finish() override {}
    std::vector<unsigned char> row_;
};

// PFM: rows are stored bottom to top, so each row goes to its own offset.
// A grey one ("Pf") keeps the first channel of each pixel.
class PfmWriter : public ImageWriter {
public:
    PfmWriter(std::string path, int width, int height, ImageLayout layout)
        : ImageWriter(std::move(path), width, height), channels_(layout == ImageLayout::Grey ? 1 : 3) {
        const std::string header = std::string(channels_ == 1 ? "Pf" : "PF") + "\n" + std::to_string(width) + " " +
                                   std::to_string(height) + "\n-1.0\n";
        headerBytes_ = static_cast<long>(header.size());
        if (std::fwrite(header.data(), 1, header.size(), file_) != header.size())
            throw ImageIOError("cannot write '" + path_ + "': " + errorText());
        if (channels_ == 1) grey_.resize(std::size_t(width));
    }
    void writeRows(const float* rgb, int rows) override {
        const long rowBytes = long(width_) * channels_ * long(sizeof(float));
        for (int r = 0; r < rows; ++r, rgb += std::size_t(width_) * 3) {
            const long y = rowsWritten_ + r;
            for (std::size_t x = 0; x < grey_.size(); ++x) grey_[x] = rgb[3 * x];
            const float* row = channels_ == 1 ? grey_.data() : rgb;
            if (std::fseek(file_, headerBytes_ + (height_ - 1 - y) * rowBytes, SEEK_SET) != 0 ||
                std::fwrite(row, 1, std::size_t(rowBytes), file_) != std::size_t(rowBytes))
                throw ImageIOError("cannot write '" + path_ + "': " + errorText());
        }
        rowsWritten_ += rows;
    }

private:
    void finish() override {}
    long headerBytes_ = 0;
    int channels_;
    std::vector<float> grey_;
};

// OpenEXR's output stream over the writer's temporary file.
class ExrFileStream : public Imf::OStream {
public:
    ExrFileStream(std::FILE* file, const std::string& name) : Imf::OStream(name.c_str()), file_(file) {}
    void write(const char c[], int n) override {
        if (std::fwrite(c, 1, std::size_t(n), file_) != std::size_t(n))
            throw ImageIOError("cannot write '" + std::string(fileName()) + "': " + errorText());
    }
    std::uint64_t tellp() override { return std::uint64_t(::ftello(file_)); }
    void seekp(std::uint64_t pos) override {
        if (::fseeko(file_, off_t(pos), SEEK_SET) != 0)
            throw ImageIOError("cannot write '" + std::string(fileName()) + "': " + errorText());
    }

private:
    std::FILE* file_;
};

// OpenEXR compresses a band's blocks on its global thread pool, which has no
// threads until it is given some: without this every block is compressed on
// the calling thread, one after the other.
void startExrThreads() {
    static std::once_flag started;
    std::call_once(started, [] { Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency()))); });
}

Imf::Compression exrLibraryCompression(ExrCompression compression) {
    switch (compression) {
    case ExrCompression::None: return Imf::NO_COMPRESSION;
    case ExrCompression::Rle: return Imf::RLE_COMPRESSION;
    case ExrCompression::Zip: return Imf::ZIP_COMPRESSION;
    case ExrCompression::Piz: return Imf::PIZ_COMPRESSION;
    }
    return Imf::RLE_COMPRESSION;
}

// OpenEXR, 32-bit float R, G, B (or Y alone, grey), scan lines written as rows
// come, compressed as asked (ExrCompression) on OpenEXR's thread pool. A piece
// of a larger image has that image as its display window and its own pixels as
// the data window; text goes into string attributes.
class ExrWriter : public ImageWriter {
public:
    ExrWriter(std::string path, int width, int height, const ImageText& text, const ImagePlacement& placement,
              ExrCompression compression, ImageLayout layout)
        : ImageWriter(std::move(path), width, height), stream_(file_, path_),
          channels_(layout == ImageLayout::Grey ? "Y" : "RGB") {
        const int fullWidth = placement.fullWidth > 0 ? placement.fullWidth : width;
        const int fullHeight = placement.fullHeight > 0 ? placement.fullHeight : height;
        origin_ = Imath::V2i(placement.x, placement.y);
        Imf::Header header(Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(fullWidth - 1, fullHeight - 1)),
                           Imath::Box2i(origin_, origin_ + Imath::V2i(width - 1, height - 1)));
        header.compression() = exrLibraryCompression(compression);
        for (char channel : channels_) header.channels().insert(std::string(1, channel), Imf::Channel(Imf::FLOAT));
        for (const auto& [key, value] : text) header.insert(key, Imf::StringAttribute(value));
        startExrThreads();
        // Two line buffers per thread keep every thread fed (OpenEXR's rule).
        guard([&] { output_ = std::make_unique<Imf::OutputFile>(stream_, header, Imf::globalThreadCount()); });
    }
    void writeRows(const float* rgb, int rows) override {
        guard([&] {
            Imf::FrameBuffer frame;
            const Imath::V2i first = origin_ + Imath::V2i(0, rowsWritten_);
            const std::size_t pixelBytes = 3 * sizeof(float);
            for (std::size_t c = 0; c < channels_.size(); ++c)
                frame.insert(std::string(1, channels_[c]), Imf::Slice::Make(Imf::FLOAT, rgb + c, first, width_, rows,
                                                                           pixelBytes, pixelBytes * width_));
            output_->setFrameBuffer(frame);
            output_->writePixels(rows);
        });
        rowsWritten_ += rows;
    }

private:
    // The line offset table is written when the OutputFile closes.
    void finish() override {
        output_.reset();
        if (std::ferror(file_)) throw ImageIOError("cannot write '" + path_ + "': " + errorText());
    }
    template <typename F>
    void guard(F f) {
        try {
            f();
        } catch (const ImageIOError&) {
            throw;
        } catch (const std::exception& e) {
            throw ImageIOError("cannot write '" + path_ + "': " + e.what());
        }
    }
    ExrFileStream stream_;
    std::unique_ptr<Imf::OutputFile> output_;
    Imath::V2i origin_;
    std::string channels_;  // their names, one letter each
};

// PNG: libpng writes the container (signature, header, the text chunks that
// name the scene and settings, CRCs); the image data is deflated here, in
// segments of rows compressed side by side on the cores and joined into one
// zlib stream, as pigz does: each segment is a raw deflate stream of its own,
// flushed to a byte boundary, and the stream's Adler-32 is combined from
// theirs. (libpng would deflate on one thread, and at zlib's level 1 that
// was most of a 512² render's 6 ms of writing.) The segments' rows depend on the
// image's size only, so the file's bytes do not depend on the cores or on
// the bands the rows arrive in.
class PngWriter : public ImageWriter {
public:
    PngWriter(std::string path, int width, int height, const ImageText& text)
        : ImageWriter(std::move(path), width, height), lineBytes_(std::size_t(width) * 3 + 1) {
        const std::size_t segments = std::max<std::size_t>(1, lineBytes_ * std::size_t(height) / kSegmentBytes);
        segmentRows_ = (std::size_t(height) + segments - 1) / segments;
        png_ = png_create_write_struct(PNG_LIBPNG_VER_STRING, this, onError, onWarning);
        info_ = png_ ? png_create_info_struct(png_) : nullptr;
        if (!png_ || !info_) throw ImageIOError("cannot start a PNG encoder (out of memory)");
        std::vector<png_text> chunks(text.size());
        for (std::size_t i = 0; i < text.size(); ++i) {
            chunks[i].compression = PNG_TEXT_COMPRESSION_NONE;
            chunks[i].key = const_cast<char*>(text[i].first.c_str());
            chunks[i].text = const_cast<char*>(text[i].second.c_str());
        }
        guard([&] {
            png_init_io(png_, file_);
            png_set_IHDR(png_, info_, std::uint32_t(width), std::uint32_t(height), 8, PNG_COLOR_TYPE_RGB,
                         PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
            if (!chunks.empty()) png_set_text(png_, info_, chunks.data(), int(chunks.size()));
            png_write_info(png_, info_);
        });
    }
    ~PngWriter() override { png_destroy_write_struct(&png_, &info_); }
    void writeRows(const float* rgb, int rows) override {
        // Fast over small: zlib's level 1 and no row filter (filter byte 0)
        // write a 512² render in a few ms instead of ~30 (the files ~25 % larger).
        // Rows wait as scanlines until their segment is whole, a few segments
        // a core at most.
        const std::size_t rowFloats = std::size_t(width_) * 3;
        const std::size_t batchRows = segmentRows_ * 2 * std::size_t(cores());
        lines_.reserve(lines_.size() + std::min(std::size_t(rows), batchRows) * lineBytes_);
        for (int r = 0; r < rows; ++r, rgb += rowFloats) {
            const std::size_t at = lines_.size();
            lines_.resize(at + lineBytes_);
            lines_[at] = 0;
            for (std::size_t i = 0; i < rowFloats; ++i) lines_[at + 1 + i] = toByte(rgb[i]);
            if (lines_.size() >= batchRows * lineBytes_) deflateSegments(false);
        }
        rowsWritten_ += rows;
        deflateSegments(false);
    }

private:
    static constexpr std::size_t kSegmentBytes = 128 * 1024;  // of scanlines: a share worth a thread
    static unsigned cores() { return std::clamp(std::thread::hardware_concurrency(), 1u, 16u); }
    struct Segment {
        std::vector<unsigned char> bytes;
        uLong adler = 1;
        bool ok = false;
    };
    // Scanlines deflated as a raw stream that ends on a byte boundary.
    static Segment deflateLines(const unsigned char* lines, std::size_t size) {
        Segment s;
        s.adler = adler32(1, lines, uInt(size));
        z_stream z{};
        if (deflateInit2(&z, 1, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) return s;
        s.bytes.resize(deflateBound(&z, uLong(size)) + 16);
        z.next_in = const_cast<unsigned char*>(lines);
        z.avail_in = uInt(size);
        z.next_out = s.bytes.data();
        z.avail_out = uInt(s.bytes.size());
        // (Room left over proves the flush complete.)
        s.ok = deflate(&z, Z_SYNC_FLUSH) == Z_OK && z.avail_in == 0 && z.avail_out != 0;
        s.bytes.resize(s.bytes.size() - z.avail_out);
        deflateEnd(&z);
        return s;
    }
    // Deflates the whole segments waiting (and, last, the short one that ends
    // the image) on up to a thread a core, and writes them in order.
    void deflateSegments(bool last) {
        const std::size_t segmentBytes = segmentRows_ * lineBytes_;
        std::size_t count = lines_.size() / segmentBytes;
        if (last && lines_.size() % segmentBytes != 0) ++count;
        if (count == 0) return;
        std::vector<Segment> parts(count);
        std::atomic<std::size_t> next{0};
        // A segment that fails (out of memory) stays not ok; every thread is
        // joined before that is reported.
        auto work = [&]() noexcept {
            for (std::size_t k; (k = next++) < count;) {
                const std::size_t begin = k * segmentBytes;
                try {
                    parts[k] = deflateLines(&lines_[begin], std::min(lines_.size(), begin + segmentBytes) - begin);
                } catch (const std::exception&) {
                    parts[k].ok = false;
                }
            }
        };
        {
            std::vector<std::jthread> helpers;
            const std::size_t threads = std::min<std::size_t>(count, cores());
            helpers.reserve(threads);
            try {
                for (std::size_t k = 1; k < threads; ++k) helpers.emplace_back(work);
            } catch (const std::system_error&) {
                // No more threads to be had: those started, and this one, do it all.
            }
            work();
        }  // (the helpers join here)
        const std::size_t used = std::min(lines_.size(), count * segmentBytes);
        for (std::size_t k = 0; k < count; ++k) {
            if (!parts[k].ok) throw ImageIOError("cannot write '" + path_ + "': zlib failed (out of memory)");
            writeData(parts[k].bytes.data(), parts[k].bytes.size());
            const std::size_t length = std::min(segmentBytes, used - k * segmentBytes);
            adler_ = adler32_combine(adler_, parts[k].adler, z_off_t(length));
        }
        lines_.erase(lines_.begin(), lines_.begin() + std::ptrdiff_t(used));
    }
    // Part of the zlib stream, as an IDAT chunk (a PNG's IDAT chunks concatenate).
    void writeData(const unsigned char* data, std::size_t size) {
        if (!headerWritten_) {
            static const unsigned char header[] = {0x78, 0x01};  // deflate, 32 KiB window, fastest
            headerWritten_ = true;
            writeData(header, sizeof header);
        }
        guard([&] { png_write_chunk(png_, reinterpret_cast<png_const_bytep>("IDAT"), data, size); });
    }
    void finish() override {
        deflateSegments(true);
        // The stream's last block (empty, final, fixed Huffman) and its Adler-32.
        const unsigned char trailer[] = {0x03, 0x00, static_cast<unsigned char>(adler_ >> 24),
                                         static_cast<unsigned char>(adler_ >> 16),
                                         static_cast<unsigned char>(adler_ >> 8), static_cast<unsigned char>(adler_)};
        writeData(trailer, sizeof trailer);
        guard([&] { png_write_chunk(png_, reinterpret_cast<png_const_bytep>("IEND"), nullptr, 0); });
    }
    // libpng reports errors by longjmp; turn them into exceptions here.
    template <typename F>
    void guard(F f) {
        if (setjmp(png_jmpbuf(png_))) throw ImageIOError("cannot write '" + path_ + "': " + message_);
        f();
    }
    static void onError(png_structp png, png_const_charp message) {
        static_cast<PngWriter*>(png_get_error_ptr(png))->message_ = message ? message : "PNG error";
        png_longjmp(png, 1);
    }
    static void onWarning(png_structp, png_const_charp) {}

    png_structp png_ = nullptr;
    png_infop info_ = nullptr;
    std::string message_;
    const std::size_t lineBytes_;  // a scanline's: its filter byte and RGB
    std::size_t segmentRows_ = 1;
    std::vector<unsigned char> lines_;  // scanlines not yet deflated
    bool headerWritten_ = false;
    uLong adler_ = 1;  // of the scanlines deflated so far
};

}  // namespace

ImageFormat formatForPath(const std::string& path) {
    if (path == kStandardOutput) return ImageFormat::Ppm;
    const std::string ext = extensionOf(path);
    if (ext == ".png") return ImageFormat::Png;
    if (ext == ".ppm") return ImageFormat::Ppm;
    if (ext == ".pfm") return ImageFormat::Pfm;
    if (ext == ".exr") return ImageFormat::Exr;
    throw ImageIOError("cannot tell the image format of '" + path +
                       "': use the extension .png, .ppm, .pfm or .exr");
}

void checkWritable(const std::string& path) {
    if (path == kStandardOutput) return;
    formatForPath(path);
    fs::path p(path);
    if (fs::is_directory(p)) throw ImageIOError("output '" + path + "' is a directory");
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw ImageIOError("cannot write '" + path + "': directory '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
        throw ImageIOError("cannot write '" + path + "': directory '" + dir.string() + "' is not writable (" +
                           errorText() + ")");
    if (fs::exists(p) && ::access(p.c_str(), W_OK) != 0)
        throw ImageIOError("cannot write '" + path + "': the file is not writable (" + errorText() + ")");
}

ImageWriter::ImageWriter(std::string path, int width, int height)
    : path_(std::move(path)), width_(width), height_(height) {
    if (path_ == kStandardOutput) {  // a pipe: rows go out as they come
        file_ = stdout;
        return;
    }
    // A unique temporary name in the same directory, so rename() is atomic.
    std::random_device random;
    temporary_ = path_ + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(random());
    file_ = std::fopen(temporary_.c_str(), "wb");
    if (!file_) throw ImageIOError("cannot create '" + temporary_ + "': " + errorText());
}

ImageWriter::~ImageWriter() {
    if (path_ == kStandardOutput) {
        std::fflush(stdout);
        return;
    }
    if (file_) std::fclose(file_);
    if (!committed_) std::remove(temporary_.c_str());
}

const char* exrCompressionName(ExrCompression compression) {
    switch (compression) {
    case ExrCompression::None: return "none";
    case ExrCompression::Rle: return "rle";
    case ExrCompression::Zip: return "zip";
    case ExrCompression::Piz: return "piz";
    }
    return "rle";
}

ExrCompression exrCompressionNamed(const std::string& name) {
    std::string names;
    for (ExrCompression c : kExrCompressions) {
        if (name == exrCompressionName(c)) return c;
        names += std::string(names.empty() ? "" : ", ") + exrCompressionName(c);
    }
    throw ImageIOError("unknown EXR compression '" + name + "' (" + names + ")");
}

std::unique_ptr<ImageWriter> ImageWriter::open(const std::string& path, int width, int height,
                                               const ImageText& text, const ImagePlacement& placement,
                                               ExrCompression compression, ImageLayout layout) {
    switch (formatForPath(path)) {
    case ImageFormat::Png: return std::unique_ptr<ImageWriter>(new PngWriter(path, width, height, text));
    case ImageFormat::Ppm: return std::unique_ptr<ImageWriter>(new PpmWriter(path, width, height));
    case ImageFormat::Pfm: return std::unique_ptr<ImageWriter>(new PfmWriter(path, width, height, layout));
    case ImageFormat::Exr:
        return std::unique_ptr<ImageWriter>(new ExrWriter(path, width, height, text, placement, compression, layout));
    }
    throw ImageIOError("unknown image format");
}

void ImageWriter::commit() {
    if (rowsWritten_ != height_)
        throw ImageIOError("internal error: " + std::to_string(rowsWritten_) + " of " + std::to_string(height_) +
                           " rows written to '" + path_ + "'");
    finish();
    if (path_ == kStandardOutput) {
        if (std::fflush(stdout) != 0) throw ImageIOError("cannot write to standard output: " + errorText());
        committed_ = true;
        return;
    }
    const bool flushed = std::fflush(file_) == 0 && ::fsync(fileno(file_)) == 0;
    const int closed = std::fclose(file_);
    file_ = nullptr;
    if (!flushed || closed != 0) throw ImageIOError("cannot write '" + path_ + "': " + errorText());
    if (std::rename(temporary_.c_str(), path_.c_str()) != 0)
        throw ImageIOError("cannot write '" + path_ + "': " + errorText());
    committed_ = true;
}

void writeImage(const std::string& path, const Image& image, const ImageText& text, const ImagePlacement& placement,
                ExrCompression compression, ImageLayout layout) {
    auto writer = ImageWriter::open(path, image.width, image.height, text, placement, compression, layout);
    writer->writeRows(image.rgb.data(), image.height);
    writer->commit();
}

namespace {

// EXR: the data window's pixels, R, G and B (a missing one reads as 0), or Y
// alone as grey; the windows and string attributes into `header`.
Image readExr(const std::string& path, ImageHeader& header) {
    try {
        Imf::InputFile file(path.c_str());
        const Imf::Header& h = file.header();
        const Imath::Box2i data = h.dataWindow();
        const Imath::Box2i display = h.displayWindow();
        Image image(data.max.x - data.min.x + 1, data.max.y - data.min.y + 1);
        const bool grey = h.channels().findChannel("Y") && !h.channels().findChannel("R") &&
                          !h.channels().findChannel("G") && !h.channels().findChannel("B");
        Imf::FrameBuffer frame;
        const std::size_t pixelBytes = 3 * sizeof(float);
        for (int c = 0; c < (grey ? 1 : 3); ++c)
            frame.insert(grey ? std::string("Y") : std::string(1, "RGB"[c]),
                         Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + c, data, pixelBytes,
                                          pixelBytes * std::size_t(image.width)));
        file.setFrameBuffer(frame);
        file.readPixels(data.min.y, data.max.y);
        if (grey)
            for (std::size_t i = 0; i < image.rgb.size(); i += 3) image.rgb[i + 1] = image.rgb[i + 2] = image.rgb[i];
        header.channels = grey ? 1 : 3;
        header.placement = {data.min.x - display.min.x, data.min.y - display.min.y, display.max.x - display.min.x + 1,
                            display.max.y - display.min.y + 1, true};
        for (auto a = h.begin(); a != h.end(); ++a)
            if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&a.attribute()))
                header.text.push_back({a.name(), text->value()});
        return image;
    } catch (const std::exception& e) {
        throw ImageIOError("cannot read EXR '" + path + "': " + e.what());
    }
}

// P6 PPM, or PFM: colour ("PF") or grey ("Pf", read as R = G = B).
Image readNetpbm(const std::string& path, const std::string& data, ImageHeader& header) {
    std::istringstream in(data);
    std::string magic;
    int w = 0, h = 0;
    double scale = 0;
    in >> magic >> w >> h >> scale;
    if (!in || w <= 0 || h <= 0 || (magic != "P6" && magic != "PF" && magic != "Pf"))
        throw ImageIOError("'" + path + "' is not a P6 PPM or PFM file");
    const std::size_t offset = static_cast<std::size_t>(in.tellg()) + 1;
    Image image(w, h);
    if (magic == "P6") {
        if (scale != 255 || data.size() < offset + image.rgb.size())
            throw ImageIOError("'" + path + "': unsupported or truncated PPM");
        for (std::size_t i = 0; i < image.rgb.size(); ++i)
            image.rgb[i] = static_cast<unsigned char>(data[offset + i]) / 255.0f;
        return image;
    }
    header.channels = magic == "Pf" ? 1 : 3;
    const std::size_t row = static_cast<std::size_t>(w) * header.channels;
    if (scale >= 0 || data.size() < offset + row * h * sizeof(float))
        throw ImageIOError("'" + path + "': unsupported (big-endian) or truncated PFM");
    std::vector<float> grey(header.channels == 1 ? row : 0);
    for (int y = 0; y < h; ++y) {
        const char* source = data.data() + offset + y * row * sizeof(float);
        if (header.channels == 3) {
            std::memcpy(image.pixel(0, h - 1 - y), source, row * sizeof(float));
            continue;
        }
        std::memcpy(grey.data(), source, row * sizeof(float));
        float* out = image.pixel(0, h - 1 - y);
        for (int x = 0; x < w; ++x) out[3 * x] = out[3 * x + 1] = out[3 * x + 2] = grey[std::size_t(x)];
    }
    return image;
}

}  // namespace

Image readImage(const std::string& path, ImagePlacement* placement) {
    ImageHeader header;
    Image image = readImage(path, &header);
    if (placement) *placement = header.placement;
    return image;
}

Image readImage(const std::string& path, ImageHeader* header) {
    ImageHeader local;
    ImageHeader& h = header ? *header : local;
    h = {};
    if (formatForPath(path) == ImageFormat::Exr) return readExr(path, h);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImageIOError("cannot open '" + path + "': " + errorText());
    std::ostringstream buffer;
    buffer << in.rdbuf();
    const std::string data = buffer.str();
    if (formatForPath(path) != ImageFormat::Png) return readNetpbm(path, data, h);
    int w, h8, channels;
    unsigned char* pixels = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(data.data()),
                                                  static_cast<int>(data.size()), &w, &h8, &channels, 3);
    if (!pixels) throw ImageIOError("cannot decode PNG '" + path + "': " + stbi_failure_reason());
    Image image(w, h8);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = pixels[i] / 255.0f;
    stbi_image_free(pixels);
    h.text = pngText(data);
    return image;
}

}  // namespace snell
