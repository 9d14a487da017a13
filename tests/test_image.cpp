// Image files (PNG, PPM, PFM), SPEC §6 byte conversion, atomic writes, and the
// error metrics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include <unistd.h>

#include "image/BoundImage.h"
#include "image/ImageIO.h"
#include "metrics/ImageMetrics.h"
#include <zlib.h>

namespace {

namespace fs = std::filesystem;
using snell::Image;
using snell::ImageIOError;

// A fresh, empty directory per test, removed afterwards.
class ImageFiles : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("snell-test-image-" + std::to_string(::getpid()) + "-" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::size_t entries() const {
        return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
    }
    static std::string slurp(const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        std::ostringstream s;
        s << in.rdbuf();
        return s.str();
    }
    fs::path dir_;
};

// 3 x 2, every channel a distinct byte value (5, 19, ..., 243), so
// orientation errors show.
Image byteImage() {
    Image image(3, 2);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = static_cast<float>(i * 14 + 5) / 255.0f;
    return image;
}

TEST_F(ImageFiles, PpmRoundTrip) {
    const Image image = byteImage();
    snell::writeImage(path("a.ppm"), image);
    const Image back = snell::readImage(path("a.ppm"));
    ASSERT_EQ(back.width, 3);
    ASSERT_EQ(back.height, 2);
    ASSERT_EQ(back.rgb.size(), image.rgb.size());
    for (std::size_t i = 0; i < image.rgb.size(); ++i) EXPECT_EQ(back.rgb[i], image.rgb[i]) << i;
    // P6 header, then the bytes, rows top to bottom.
    const std::string data = slurp(path("a.ppm"));
    const std::string header = "P6\n3 2\n255\n";
    ASSERT_EQ(data.rfind(header, 0), 0u);
    ASSERT_EQ(data.size(), header.size() + 18);
    for (std::size_t i = 0; i < 18; ++i)
        EXPECT_EQ(static_cast<unsigned char>(data[header.size() + i]), i * 14 + 5) << i;
    EXPECT_EQ(entries(), 1u);  // no temporary left behind
}

TEST_F(ImageFiles, PngRoundTrip) {
    const Image image = byteImage();
    snell::writeImage(path("a.png"), image);
    const Image back = snell::readImage(path("a.png"));
    ASSERT_EQ(back.width, 3);
    ASSERT_EQ(back.height, 2);
    ASSERT_EQ(back.rgb.size(), image.rgb.size());
    for (std::size_t i = 0; i < image.rgb.size(); ++i) EXPECT_EQ(back.rgb[i], image.rgb[i]) << i;
    EXPECT_EQ(slurp(path("a.png")).substr(1, 3), "PNG");
    EXPECT_EQ(entries(), 1u);
}

TEST_F(ImageFiles, EightBitFormatsClamp) {
    Image image(2, 2);
    const float values[12] = {1.5f, -0.3f, 0.0f, 1.0f, 100.0f, std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                              0.5f, 2.0f, 0.25f, 1e-9f};
    std::copy(values, values + 12, image.rgb.begin());
    // 0.25 * 255 = 63.75 -> 64; 0.5 * 255 = 127.5 -> 128 (halves up).
    const float expected[12] = {1, 0, 0, 1, 1, 0, 1, 0, 128 / 255.0f, 1, 64 / 255.0f, 0};
    for (const char* name : {"c.ppm", "c.png"}) {
        SCOPED_TRACE(name);
        snell::writeImage(path(name), image);
        const Image back = snell::readImage(path(name));
        ASSERT_EQ(back.rgb.size(), 12u);
        for (int i = 0; i < 12; ++i) EXPECT_EQ(back.rgb[i], expected[i]) << i;
    }
}

TEST_F(ImageFiles, PfmRoundTripIsExactAndUnclamped) {
    Image image(3, 2);
    const float values[18] = {3.5f, -2.25f, 1e-7f, 1e30f, 0.0f, -0.0f, 1.0f / 3.0f, 255.75f, -1e-20f,
                              0.5f, 7.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, -7.0f};
    std::copy(values, values + 18, image.rgb.begin());
    snell::writeImage(path("f.pfm"), image);
    const Image back = snell::readImage(path("f.pfm"));
    ASSERT_EQ(back.width, 3);
    ASSERT_EQ(back.height, 2);
    ASSERT_EQ(back.rgb.size(), 18u);
    for (int i = 0; i < 18; ++i) {
        EXPECT_EQ(back.rgb[i], values[i]) << i;
        EXPECT_EQ(std::signbit(back.rgb[i]), std::signbit(values[i])) << i;
    }
    // Little-endian PFM, rows stored bottom to top: the first float stored is
    // the first pixel of the bottom row (row 1), i.e. value 9.
    const std::string data = slurp(path("f.pfm"));
    const std::string header = "PF\n3 2\n-1.0\n";
    ASSERT_EQ(data.rfind(header, 0), 0u);
    ASSERT_EQ(data.size(), header.size() + 18 * sizeof(float));
    float first;
    std::memcpy(&first, data.data() + header.size(), sizeof first);
    EXPECT_EQ(first, values[9]);
}

TEST(ToByte, RoundingAndClamping) {
    EXPECT_EQ(snell::toByte(0.0f), 0);
    EXPECT_EQ(snell::toByte(1.0f), 255);
    EXPECT_EQ(snell::toByte(-1.0f), 0);
    EXPECT_EQ(snell::toByte(-0.0f), 0);
    EXPECT_EQ(snell::toByte(2.0f), 255);
    EXPECT_EQ(snell::toByte(std::numeric_limits<float>::infinity()), 255);
    EXPECT_EQ(snell::toByte(-std::numeric_limits<float>::infinity()), 0);
    EXPECT_EQ(snell::toByte(std::numeric_limits<float>::quiet_NaN()), 0);
    // 255 * 0.5 = 127.5 exactly: halves round up.
    EXPECT_EQ(snell::toByte(0.5f), 128);
    // Every k/255 maps back to k.
    for (int k = 0; k <= 255; ++k) EXPECT_EQ(snell::toByte(k / 255.0f), k) << k;
}

TEST(ToByte, HalfStepBoundaries) {
    // The floats on either side of (k + 0.5)/255 round down and up.
    // (127.5/255 = 0.5 is an exact half: see RoundingAndClamping.)
    for (int k : {0, 1, 100, 200, 254}) {
        SCOPED_TRACE(k);
        const double half = (k + 0.5) / 255.0;
        float below = static_cast<float>(half);
        if (static_cast<double>(below) * 255.0 >= k + 0.5) below = std::nextafter(below, 0.0f);
        const float above = std::nextafter(below, 1.0f);
        ASSERT_LT(static_cast<double>(below) * 255.0, k + 0.5);
        ASSERT_GT(static_cast<double>(above) * 255.0, k + 0.5);
        EXPECT_EQ(snell::toByte(below), k);
        EXPECT_EQ(snell::toByte(above), k + 1);
    }
}

TEST_F(ImageFiles, WriteIntoMissingDirectoryThrowsAndLeavesNothing) {
    const std::string target = path("missing/sub/x.png");
    EXPECT_THROW(snell::writeImage(target, byteImage()), ImageIOError);
    EXPECT_FALSE(fs::exists(target));
    EXPECT_FALSE(fs::exists(path("missing")));
    EXPECT_EQ(entries(), 0u);
    EXPECT_THROW(snell::checkWritable(target), ImageIOError);
    EXPECT_NO_THROW(snell::checkWritable(path("fine.png")));
}

TEST_F(ImageFiles, ExistingFileReplacedOnlyOnSuccess) {
    const std::string target = path("out.ppm");
    { std::ofstream(target) << "precious"; }
    snell::writeImage(target, byteImage());
    EXPECT_EQ(slurp(target).rfind("P6\n", 0), 0u);
    EXPECT_EQ(entries(), 1u);

    // A failing write (unknown format) leaves an existing file untouched.
    const std::string jpg = path("out.jpg");
    { std::ofstream(jpg) << "precious"; }
    EXPECT_THROW(snell::writeImage(jpg, byteImage()), ImageIOError);
    EXPECT_EQ(slurp(jpg), "precious");

    // A failing rename (the target is a non-empty directory) leaves it, and
    // no temporary file.
    const std::string asDir = path("dir.png");
    fs::create_directories(fs::path(asDir) / "keep");
    EXPECT_THROW(snell::writeImage(asDir, byteImage()), ImageIOError);
    EXPECT_TRUE(fs::is_directory(fs::path(asDir) / "keep"));
    EXPECT_EQ(entries(), 3u);  // out.ppm, out.jpg, dir.png
    EXPECT_THROW(snell::checkWritable(asDir), ImageIOError);
}

TEST_F(ImageFiles, ExrRoundTripIsExactAndUnclamped) {
    Image image(3, 2);
    const float values[18] = {3.5f, -2.25f, 1e-7f, 1e30f, 0.0f, -0.0f, 1.0f / 3.0f, 255.75f, -1e-20f,
                              0.5f, 7.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, -7.0f};
    std::copy(values, values + 18, image.rgb.begin());
    snell::writeImage(path("f.exr"), image);
    EXPECT_EQ(slurp(path("f.exr")).substr(0, 4), std::string("\x76\x2f\x31\x01"));  // OpenEXR magic
    const Image back = snell::readImage(path("f.exr"));
    ASSERT_EQ(back.width, 3);
    ASSERT_EQ(back.height, 2);
    for (int i = 0; i < 18; ++i) EXPECT_EQ(back.rgb[i], values[i]) << i;
}

// A piece of a larger image: EXR keeps where it lies (data window inside the
// display window) and its rows, written in several calls, in order.
TEST_F(ImageFiles, ExrKeepsItsPlacementAndStreamsRows) {
    Image image(4, 3);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = float(i) * 0.25f - 1.0f;
    auto writer = snell::ImageWriter::open(path("piece.exr"), 4, 3, {{"Region", "5 7 of 16x20"}}, {5, 7, 16, 20});
    writer->writeRows(image.rgb.data(), 1);
    writer->writeRows(image.pixel(0, 1), 2);
    writer->commit();
    snell::ImagePlacement placement;
    const Image back = snell::readImage(path("piece.exr"), &placement);
    EXPECT_TRUE(placement.stored);
    EXPECT_EQ(placement.x, 5);
    EXPECT_EQ(placement.y, 7);
    EXPECT_EQ(placement.fullWidth, 16);
    EXPECT_EQ(placement.fullHeight, 20);
    ASSERT_EQ(back.width, 4);
    ASSERT_EQ(back.height, 3);
    EXPECT_EQ(back.rgb, image.rgb);
    // Formats without a window say so.
    snell::writeImage(path("piece.pfm"), image);
    snell::readImage(path("piece.pfm"), &placement);
    EXPECT_FALSE(placement.stored);
}

TEST(ImageFormat, ByExtension) {
    EXPECT_EQ(snell::formatForPath("a.png"), snell::ImageFormat::Png);
    EXPECT_EQ(snell::formatForPath("dir.x/a.ppm"), snell::ImageFormat::Ppm);
    EXPECT_EQ(snell::formatForPath("a.pfm"), snell::ImageFormat::Pfm);
    EXPECT_EQ(snell::formatForPath("a.exr"), snell::ImageFormat::Exr);
    EXPECT_EQ(snell::formatForPath("-"), snell::ImageFormat::Ppm);
    EXPECT_EQ(snell::formatForPath("A.PNG"), snell::ImageFormat::Png);
    EXPECT_THROW(snell::formatForPath("a.jpg"), ImageIOError);
    EXPECT_THROW(snell::formatForPath("a.png.jpg"), ImageIOError);
    EXPECT_THROW(snell::formatForPath("noextension"), ImageIOError);
    EXPECT_THROW(snell::formatForPath("png"), ImageIOError);
    try {
        snell::formatForPath("x.jpg");
    } catch (const ImageIOError& e) {
        EXPECT_NE(std::string(e.what()).find(".png"), std::string::npos) << e.what();
    }
}

TEST_F(ImageFiles, ReadErrors) {
    EXPECT_THROW(snell::readImage(path("none.ppm")), ImageIOError);
    { std::ofstream(path("short.ppm"), std::ios::binary) << "P6\n4 4\n255\nabc"; }
    EXPECT_THROW(snell::readImage(path("short.ppm")), ImageIOError);
    { std::ofstream(path("bad.pfm"), std::ios::binary) << "P3\n1 1\n255\n0 0 0\n"; }
    EXPECT_THROW(snell::readImage(path("bad.pfm")), ImageIOError);
    { std::ofstream(path("bad.png"), std::ios::binary) << "not a png at all"; }
    EXPECT_THROW(snell::readImage(path("bad.png")), ImageIOError);
}

// ---------------------------------------------------------------- metrics

// Channels given as 8-bit values (non-finite values kept as they are).
Image fromBytes(int w, int h, std::initializer_list<float> bytes) {
    Image image(w, h);
    std::size_t i = 0;
    for (float b : bytes) image.rgb[i++] = std::isfinite(b) ? b / 255.0f : b;
    return image;
}

TEST(Metrics, HandMadePair) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Image reference = fromBytes(2, 2, {100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100});
    // Differences per channel: pixel 0 none, pixel 1 r +2, pixel 2 g -10,
    // pixel 3 b NaN (-> byte 0: 100).
    const Image test = fromBytes(2, 2, {100, 100, 100, 102, 100, 100, 100, 90, 100, 100, 100, nan});
    const snell::ImageMetrics m = snell::compareImages(test, reference);
    EXPECT_EQ(m.pixels, 4u);
    EXPECT_NEAR(m.meanAbsError, 112.0 / 12.0, 1e-12);
    EXPECT_NEAR(m.rmse, std::sqrt((4.0 + 100.0 + 10000.0) / 12.0), 1e-12);
    EXPECT_NEAR(m.psnr, 20.0 * std::log10(255.0 / m.rmse), 1e-9);
    EXPECT_EQ(m.maxError, 100);
    EXPECT_EQ(m.badPixels, 2u);  // threshold 3: pixels 2 and 3
    EXPECT_DOUBLE_EQ(m.badFraction, 0.5);
    EXPECT_EQ(m.nonFinite, 1u);
    EXPECT_NE(m.json().find("\"non_finite\": 1"), std::string::npos) << m.json();
    EXPECT_NE(m.json().find("\"max_error\": 100"), std::string::npos) << m.json();

    // A difference equal to the threshold is not bad.
    EXPECT_EQ(snell::compareImages(test, reference, 10).badPixels, 1u);
    EXPECT_EQ(snell::compareImages(test, reference, 1).badPixels, 3u);
    EXPECT_EQ(snell::compareImages(test, reference, 2).badPixels, 2u);
}

TEST(Metrics, IdenticalAndClampedImages) {
    const Image a = fromBytes(1, 2, {1, 2, 3, 4, 5, 6});
    const snell::ImageMetrics same = snell::compareImages(a, a);
    EXPECT_EQ(same.meanAbsError, 0.0);
    EXPECT_EQ(same.maxError, 0);
    EXPECT_EQ(same.badPixels, 0u);
    EXPECT_TRUE(std::isinf(same.psnr));
    EXPECT_NE(same.json().find("\"psnr\": null"), std::string::npos) << same.json();
    // Values above 1 compare after clamping: 1.0 and 7.0 are the same 8-bit colour.
    Image b(1, 1), c(1, 1);
    b.rgb = {1.0f, 0.0f, 0.5f};
    c.rgb = {7.0f, -3.0f, 0.5f};
    const snell::ImageMetrics clamped = snell::compareImages(c, b);
    EXPECT_EQ(clamped.maxError, 0);
    EXPECT_EQ(clamped.nonFinite, 0u);
}

TEST(Metrics, SizeMismatchThrows) {
    EXPECT_THROW(snell::compareImages(Image(2, 3), Image(3, 2)), std::invalid_argument);
}

TEST(Metrics, DifferenceImage) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Image reference = fromBytes(3, 1, {100, 100, 100, 100, 100, 100, 100, 100, 100});
    const Image test = fromBytes(3, 1, {100, 100, 100, 200, 100, 100, nan, 100, 100});
    const Image d = snell::differenceImage(test, reference);
    ASSERT_EQ(d.width, 3);
    ASSERT_EQ(d.height, 1);
    ASSERT_EQ(d.rgb.size(), 9u);
    // Equal: black. Far off (100 >= 16): full red. NaN: magenta.
    EXPECT_EQ(d.pixel(0, 0)[0], 0.0f);
    EXPECT_EQ(d.pixel(0, 0)[1], 0.0f);
    EXPECT_EQ(d.pixel(0, 0)[2], 0.0f);
    EXPECT_EQ(d.pixel(1, 0)[0], 1.0f);
    EXPECT_EQ(d.pixel(1, 0)[2], 0.0f);
    EXPECT_EQ(d.pixel(2, 0)[0], 1.0f);
    EXPECT_EQ(d.pixel(2, 0)[1], 0.0f);
    EXPECT_EQ(d.pixel(2, 0)[2], 1.0f);
    // A small difference is bluer than a large one.
    const Image small = fromBytes(3, 1, {101, 100, 100, 100, 100, 100, 100, 100, 100});
    const Image ds = snell::differenceImage(small, reference);
    EXPECT_GT(ds.pixel(0, 0)[2], ds.pixel(0, 0)[0]);
    EXPECT_GT(ds.pixel(0, 0)[0], 0.0f);
    // Same size as a non-square input.
    EXPECT_EQ(snell::differenceImage(Image(4, 7), Image(4, 7)).rgb.size(), 4u * 7u * 3u);
}

}  // namespace

namespace {

// Streaming: rows given in several bands give the same file as one call, for
// every format (PFM stores rows bottom to top, so bands land at offsets).
TEST_F(ImageFiles, StreamedRowsMatchWholeImage) {
    Image image(5, 7);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = static_cast<float>(i) / 100.0f;
    for (const char* ext : {".png", ".ppm", ".pfm"}) {
        SCOPED_TRACE(ext);
        snell::writeImage(path(std::string("whole") + ext), image);
        auto writer = snell::ImageWriter::open(path(std::string("bands") + ext), 5, 7);
        writer->writeRows(image.pixel(0, 0), 3);
        writer->writeRows(image.pixel(0, 3), 1);
        writer->writeRows(image.pixel(0, 4), 3);
        writer->commit();
        EXPECT_EQ(slurp(path(std::string("bands") + ext)), slurp(path(std::string("whole") + ext)));
    }
}

// A PNG large enough to be deflated in several segments side by side holds
// one zlib stream (checked by zlib itself, Adler-32 included) of its
// scanlines, reads back as its bytes, and its file does not depend on the bands.
TEST_F(ImageFiles, PngOfManySegmentsReadsBackAndIgnoresBands) {
    const int width = 256, height = 701;  // 769-byte scanlines: 4 segments of 176 rows, the last of 173
    Image image(width, height);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = float((i * 7919) % 1000) / 900.0f - 0.05f;
    snell::writeImage(path("whole.png"), image);
    auto writer = snell::ImageWriter::open(path("bands.png"), width, height);
    int row = 0;
    for (int band : {1, 170, 3, 400, 127}) {
        writer->writeRows(image.pixel(0, row), band);
        row += band;
    }
    writer->commit();
    const std::string file = slurp(path("whole.png"));
    EXPECT_EQ(slurp(path("bands.png")), file);

    // The IDAT chunks' data, joined, inflates to the scanlines: filter byte 0, then RGB bytes.
    std::string stream;
    for (std::size_t at = 8; at + 12 <= file.size();) {
        const auto byte = [&](std::size_t k) { return std::uint32_t(static_cast<unsigned char>(file[k])); };
        const std::uint32_t length = byte(at) << 24 | byte(at + 1) << 16 | byte(at + 2) << 8 | byte(at + 3);
        if (file.compare(at + 4, 4, "IDAT") == 0) stream += file.substr(at + 8, length);
        at += 12 + length;
    }
    const std::size_t lineBytes = std::size_t(width) * 3 + 1;
    std::vector<unsigned char> lines(lineBytes * height + 1);
    uLongf size = uLongf(lines.size());
    ASSERT_EQ(uncompress(lines.data(), &size, reinterpret_cast<const Bytef*>(stream.data()), uLong(stream.size())), Z_OK);
    ASSERT_EQ(size, lineBytes * height);
    std::size_t wrong = 0;
    for (int y = 0; y < height; ++y) {
        wrong += lines[std::size_t(y) * lineBytes] != 0;
        for (std::size_t i = 0; i + 1 < lineBytes; ++i)
            wrong += lines[std::size_t(y) * lineBytes + 1 + i] != snell::toByte(image.rgb[std::size_t(y) * (lineBytes - 1) + i]);
    }
    EXPECT_EQ(wrong, 0u);

    const Image back = snell::readImage(path("whole.png"));
    ASSERT_EQ(back.width, width);
    ASSERT_EQ(back.height, height);
    wrong = 0;
    for (std::size_t i = 0; i < image.rgb.size(); ++i)
        wrong += float(snell::toByte(image.rgb[i])) / 255.0f != back.rgb[i];
    EXPECT_EQ(wrong, 0u);
}

// An abandoned writer (an error or Ctrl-C mid-render) leaves no file at all.
TEST_F(ImageFiles, UncommittedWriterLeavesNothing) {
    {
        auto writer = snell::ImageWriter::open(path("partial.png"), 4, 4);
        Image rows(4, 2);
        writer->writeRows(rows.rgb.data(), 2);
    }
    EXPECT_EQ(entries(), 0u);
}

// PNG output carries the scene name and settings as text chunks.
TEST_F(ImageFiles, PngTextChunks) {
    snell::writeImage(path("t.png"), Image(2, 2), {{"Title", "showcase"}, {"Comment", "size 2"}});
    const std::string bytes = slurp(path("t.png"));
    EXPECT_NE(bytes.find(std::string("tEXtTitle\0showcase", 18)), std::string::npos);
    EXPECT_NE(bytes.find(std::string("tEXtComment\0size 2", 18)), std::string::npos);
}

// Grey files (a quantity per pixel) keep one channel, exactly, sign and all,
// and read back as R = G = B; the text of PNG and EXR files reads back.
TEST_F(ImageFiles, GreyFilesAndTextReadBack) {
    Image image(2, 1);
    image.rgb = {0.25f, 9.0f, 9.0f, -0.0f, 9.0f, 9.0f};
    const snell::ImageText text{{"Content", "a test"}, {"Region", "1 2 of 8x8"}};
    for (const char* name : {"g.pfm", "g.exr"}) {
        snell::writeImage(path(name), image, text, {}, snell::kDefaultExrCompression, snell::ImageLayout::Grey);
        snell::ImageHeader header;
        const Image back = snell::readImage(path(name), &header);
        EXPECT_EQ(header.channels, 1) << name;
        EXPECT_EQ(back.rgb[0], 0.25f) << name;
        EXPECT_EQ(back.rgb[2], 0.25f) << name;
        EXPECT_TRUE(std::signbit(back.rgb[3]) && back.rgb[5] == 0.0f) << name;
    }
    EXPECT_EQ(slurp(path("g.pfm")).substr(0, 3), "Pf\n");
    snell::writeImage(path("t.png"), image, text);
    for (const char* name : {"t.png", "g.exr"}) {
        snell::ImageHeader header;
        snell::readImage(path(name), &header);
        EXPECT_NE(std::find(header.text.begin(), header.text.end(), text[1]), header.text.end()) << name;
    }
}

// A bound image keeps bounds and marks estimates by their sign; compare's
// reader refuses what is not one, by name.
TEST_F(ImageFiles, BoundImageRoundTripAndRefusals) {
    const float none = std::numeric_limits<float>::infinity();
    for (const char* name : {"b.pfm", "b.exr"}) {
        snell::writeBoundImage(path(name), 3, 1, {0.001f, 0.5f, 0.7f}, {none, 0.002f, none}, {},
                               snell::kDefaultExrCompression);
        const snell::BoundImage b = snell::readBoundImage(path(name));
        ASSERT_EQ(b.values.size(), 3u) << name;
        EXPECT_EQ(b.values[0], 0.001f) << name;
        EXPECT_TRUE(snell::isEstimate(b.values[1]) && b.values[1] == -0.002f) << name;
        EXPECT_EQ(b.values[2], 0.7f) << name;
        EXPECT_TRUE(b.note.empty()) << name;
    }
    snell::writeBoundImage(path("b.png"), 3, 1, {0.0f, 0.5f, 0.7f}, {}, {}, snell::kDefaultExrCompression);
    EXPECT_THROW(snell::readBoundImage(path("b.png")), ImageIOError);
    snell::writeImage(path("colour.pfm"), byteImage());
    EXPECT_THROW(snell::readBoundImage(path("colour.pfm")), ImageIOError);
    Image grey(2, 1);
    grey.rgb = {0.1f, 0.1f, 0.1f, 0.2f, 0.2f, 0.2f};
    snell::writeImage(path("render.exr"), grey, {{"Source", "scenes/x.scn"}});
    try {
        snell::readBoundImage(path("render.exr"));
        ADD_FAILURE() << "a render read as a bound image";
    } catch (const ImageIOError& e) {
        EXPECT_NE(std::string(e.what()).find("render.exr' is a render of 'scenes/x.scn'"), std::string::npos) << e.what();
    }
    // An earlier snell's: RGB, equal channels, no scene named.
    snell::writeImage(path("old.pfm"), grey);
    const snell::BoundImage old = snell::readBoundImage(path("old.pfm"));
    EXPECT_EQ(old.values, (std::vector<float>{0.1f, 0.2f}));
    EXPECT_FALSE(old.note.empty());
}

// With a bound image: certified pixels compared as without one, estimated ones
// held to their estimate (bad beyond it, counted), others left out unless the
// bound proves them wrong; comparing nothing has no PSNR.
TEST(Metrics, HeldToEstimatesAndBounds) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Image reference = fromBytes(6, 1, {100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100,
                                             100, 100, 100, 100});
    const Image test = fromBytes(6, 1, {104, 100, 100, 102, 100, 100, 106, 100, 100, 104, 100, 100, 106, 100, 100,
                                        110, 100, 100});
    snell::BoundImage bound{6, 1, {0.0f, -0.3f / 255, -1.5f / 255, 1.9f / 255, 1.9f / 255, nan}, {}};
    const snell::ImageMetrics m = snell::compareImages(test, reference, 3, &bound);
    // 0: certified, off by 4: bad. 1: estimate 0.3/255, off by 2: fine.
    // 2: estimate 1.5/255 (2 steps), off by 6: bad. 3: bound 1.9/255, off by 4:
    // left out. 4: off by 6 > 2 + 3: proven wrong. 5: NaN bound: left out.
    EXPECT_EQ(m.pixels, 4u);
    EXPECT_EQ(m.uncertain, 2u);
    EXPECT_EQ(m.estimated, 2u);
    EXPECT_EQ(m.estimatedBad, 1u);
    EXPECT_EQ(m.badPixels, 3u);
    snell::BoundImage unknown{6, 1, std::vector<float>(6, 1.0f), {}};
    const snell::ImageMetrics none = snell::compareImages(reference, reference, 3, &unknown);
    EXPECT_EQ(none.pixels, 0u);
    EXPECT_TRUE(std::isnan(none.psnr));
}

}  // namespace
