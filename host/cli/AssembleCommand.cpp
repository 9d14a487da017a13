// `snell assemble`: pieces rendered with render --region into one image.
// Every pixel must be covered, by one piece only. A piece is X,Y:FILE (its
// top-left pixel in the whole image), or an EXR FILE alone, placed by its data
// window. The pieces are pixels of the same render, so the result is the whole
// render, bit for bit; what the files record of their render (PNG text, EXR
// windows and attributes, from render --region) must agree, and an offending
// file is named.
#include <algorithm>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "cli/Command.h"
#include "cli/ExitStatus.h"
#include "cli/Options.h"
#include "image/ImageIO.h"
#include "scene/Parser.h"

#ifndef SNELL_VERSION
#define SNELL_VERSION "0.0.0"
#endif

namespace snell::cli {
namespace {

// Where a piece says it lies: its top-left pixel and its render's whole size.
struct Recorded {
    int x = 0, y = 0, width = 0, height = 0;
};

struct Piece {
    std::string file;
    int x = 0, y = 0;
    Image image;
    ImageHeader header;
    std::optional<Recorded> recorded;
    std::string text(const std::string& key) const {
        for (const auto& [k, v] : header.text)
            if (k == key) return v;
        return {};
    }
    std::string where() const { return "'" + file + "' at " + std::to_string(x) + "," + std::to_string(y); }
};

// An EXR's windows, or the "Region" text render --region writes ("X Y of WxH").
std::optional<Recorded> recordedPlace(const Piece& p) {
    if (p.header.placement.stored)
        return Recorded{p.header.placement.x, p.header.placement.y, p.header.placement.fullWidth,
                        p.header.placement.fullHeight};
    std::istringstream region(p.text("Region"));
    Recorded r;
    std::string of;
    char times = 0;
    if (region >> r.x >> r.y >> of >> r.width >> times >> r.height && of == "of" && times == 'x') return r;
    return std::nullopt;
}

// X,Y:FILE, or FILE placed by its own data window.
Piece readPiece(const std::string& arg) {
    Piece p;
    const auto colon = arg.find(':');
    const auto comma = arg.find(',');
    const bool placed = colon != std::string::npos && comma != std::string::npos && comma < colon;
    if (placed) {
        char* end = nullptr;
        p.x = int(std::strtol(arg.c_str(), &end, 10));
        bool ok = end == arg.c_str() + comma;
        p.y = int(std::strtol(arg.c_str() + comma + 1, &end, 10));
        ok = ok && end == arg.c_str() + colon && p.x >= 0 && p.y >= 0;
        if (!ok) throw InputError("a piece is X,Y:FILE (its top-left pixel, then the file), got '" + arg + "'");
    }
    p.file = placed ? arg.substr(colon + 1) : arg;
    p.image = readImage(p.file, &p.header);
    p.recorded = recordedPlace(p);
    if (placed) {
        if (p.recorded && (p.recorded->x != p.x || p.recorded->y != p.y))
            throw InputError("'" + p.file + "' is the piece at " + std::to_string(p.recorded->x) + "," +
                             std::to_string(p.recorded->y) + " of its render, but is placed at " +
                             std::to_string(p.x) + "," + std::to_string(p.y) + "; nothing written");
        return p;
    }
    if (!p.header.placement.stored)
        throw InputError("'" + arg + "' does not say where it goes (only EXR keeps its window): give it as X,Y:FILE");
    if (p.header.placement.x < 0 || p.header.placement.y < 0)
        throw InputError("'" + arg + "' lies outside its display window");
    p.x = p.header.placement.x;
    p.y = p.header.placement.y;
    return p;
}

std::string size(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

// Pieces of one render: the same whole size, scene and settings where both
// files record them.
void requireSameRender(const Piece& a, const Piece& b) {
    if (a.recorded && b.recorded &&
        (a.recorded->width != b.recorded->width || a.recorded->height != b.recorded->height))
        throw InputError("'" + a.file + "' is a piece of a " + size(a.recorded->width, a.recorded->height) +
                         " render and '" + b.file + "' of a " + size(b.recorded->width, b.recorded->height) +
                         " one; nothing written");
    for (const char* key : {"Source", "Comment"}) {
        const std::string ta = a.text(key), tb = b.text(key);
        if (!ta.empty() && !tb.empty() && ta != tb)
            throw InputError("'" + a.file + "' and '" + b.file + "' are pieces of different renders (" +
                             (std::string(key) == "Source" ? "scene '" : "settings '") + ta + "' against '" + tb +
                             "'); nothing written");
    }
}

void requireApart(const Piece& a, const Piece& b) {
    const int x0 = std::max(a.x, b.x), x1 = std::min(a.x + a.image.width, b.x + b.image.width);
    const int y0 = std::max(a.y, b.y), y1 = std::min(a.y + a.image.height, b.y + b.image.height);
    if (x0 < x1 && y0 < y1)
        throw InputError("pieces " + a.where() + " and " + b.where() + " (each " + size(a.image.width, a.image.height) +
                         (a.image.width == b.image.width && a.image.height == b.image.height
                              ? ""
                              : " and " + size(b.image.width, b.image.height)) +
                         ") overlap in " + size(x1 - x0, y1 - y0) + " pixels from " + std::to_string(x0) + "," +
                         std::to_string(y0) + "; nothing written");
}

class AssembleCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override {
        CLI::App* c = app.add_subcommand(
            "assemble",
            "Join pieces rendered with render --region into one image; pieces that overlap, or that their files "
            "(PNG text, EXR windows) show to come from different renders or to belong elsewhere, are refused");
        c->add_option("-o,--output", output_, "The whole image (.png, .ppm, .pfm or .exr)")
            ->required()->check(kImageFormat);
        c->add_option("pieces", pieces_,
                      "Each piece as X,Y:FILE, X and Y its top-left pixel (X0 and Y0 of its --region), or an EXR "
                      "file alone (placed by its data window)")
            ->required();
        c->add_option("-s,--size", size_,
                      "The whole image's size, so a missing piece is an error (default: the size the pieces record, "
                      "else their extent)")
            ->check(wholeNumber(1, ParseLimits::kMaxImageSize));
        addEncodingOptions(*c, encoding_);
        return c;
    }

    int run() override {
        std::vector<Piece> pieces;
        for (const std::string& arg : pieces_) pieces.push_back(readPiece(arg));
        for (std::size_t i = 0; i < pieces.size(); ++i)
            for (std::size_t j = i + 1; j < pieces.size(); ++j) {
                requireSameRender(pieces[i], pieces[j]);
                requireApart(pieces[i], pieces[j]);
            }
        int width = 0, height = 0;
        for (const Piece& p : pieces) {
            // The whole image's size, as the pieces record it, unless -s says it.
            if (p.recorded && size_ > 0 && (p.recorded->width != size_ || p.recorded->height != size_))
                throw InputError("'" + p.file + "' is a piece of a " + size(p.recorded->width, p.recorded->height) +
                                 " render, not of --size " + std::to_string(size_) + "; nothing written");
            if (p.recorded) {
                width = std::max(width, p.recorded->width);
                height = std::max(height, p.recorded->height);
            }
            width = std::max(width, p.x + p.image.width);
            height = std::max(height, p.y + p.image.height);
        }
        if (size_ > 0) {
            if (width > size_ || height > size_)
                throw InputError("the pieces reach " + size(width, height) + ", beyond --size " + std::to_string(size_));
            width = height = size_;
        }
        const Image whole = join(pieces, width, height);
        writeImage(output_, whole, {{"Software", std::string("snell ") + SNELL_VERSION + " assemble"}}, {},
                   encoding_.exr());
        return kExitSuccess;
    }

private:
    static Image join(const std::vector<Piece>& pieces, int width, int height) {
        Image whole(width, height);
        std::vector<char> covered(std::size_t(width) * height, 0);
        for (const Piece& p : pieces) {
            for (int y = 0; y < p.image.height; ++y) {
                std::copy_n(p.image.pixel(0, y), std::size_t(p.image.width) * 3, whole.pixel(p.x, p.y + y));
                std::fill_n(covered.begin() + std::size_t(p.y + y) * width + p.x, p.image.width, 1);
            }
        }
        const auto missing = std::count(covered.begin(), covered.end(), 0);
        if (missing > 0) {
            const auto first = std::size_t(std::find(covered.begin(), covered.end(), 0) - covered.begin());
            throw InputError("the pieces leave " + std::to_string(missing) + " of the " + size(width, height) +
                             " pixels uncovered, the first at " + std::to_string(first % width) + "," +
                             std::to_string(first / width) + "; nothing written");
        }
        return whole;
    }

    std::string output_;
    std::vector<std::string> pieces_;
    int size_ = 0;
    EncodingOptions encoding_;
};

}  // namespace

std::unique_ptr<Command> makeAssembleCommand() { return std::make_unique<AssembleCommand>(); }

}  // namespace snell::cli
