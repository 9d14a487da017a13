// `snell assemble`: pieces rendered with render --region into one image.
// Every pixel must be covered. A piece is X,Y:FILE (its top-left pixel in the
// whole image), or an EXR FILE alone, placed by its data window. The pieces
// are pixels of the same render, so the result is the whole render, bit for bit.
#include <algorithm>
#include <cstdlib>

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

struct Piece {
    int x = 0, y = 0;
    Image image;
    ImagePlacement placement;  // as the file states it (EXR only)
    bool placedByFile = false;  // given as FILE alone, placed by its data window
};

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
    p.image = readImage(placed ? arg.substr(colon + 1) : arg, &p.placement);
    if (placed) return p;
    if (!p.placement.stored)
        throw InputError("'" + arg + "' does not say where it goes (only EXR keeps its window): give it as X,Y:FILE");
    if (p.placement.x < 0 || p.placement.y < 0) throw InputError("'" + arg + "' lies outside its display window");
    p.x = p.placement.x;
    p.y = p.placement.y;
    p.placedByFile = true;
    return p;
}

class AssembleCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override {
        CLI::App* c = app.add_subcommand("assemble", "Join pieces rendered with render --region into one image");
        c->add_option("-o,--output", output_, "The whole image (.png, .ppm, .pfm or .exr)")
            ->required()->check(kImageFormat);
        c->add_option("pieces", pieces_,
                      "Each piece as X,Y:FILE, X and Y its top-left pixel (X0 and Y0 of its --region), or an EXR "
                      "file alone (placed by its data window)")
            ->required();
        c->add_option("-s,--size", size_,
                      "The whole image's size, so a missing piece is an error (default: the extent of the pieces)")
            ->check(wholeNumber(1, ParseLimits::kMaxImageSize));
        addEncodingOptions(*c, encoding_);
        return c;
    }

    int run() override {
        std::vector<Piece> pieces;
        int width = 0, height = 0;
        for (const std::string& arg : pieces_) {
            Piece p = readPiece(arg);
            // The whole image's size, from the display window, unless -s says it.
            if (p.placedByFile && size_ == 0) {
                width = std::max(width, p.placement.fullWidth);
                height = std::max(height, p.placement.fullHeight);
            }
            width = std::max(width, p.x + p.image.width);
            height = std::max(height, p.y + p.image.height);
            pieces.push_back(std::move(p));
        }
        if (size_ > 0) {
            if (width > size_ || height > size_)
                throw InputError("the pieces reach " + std::to_string(width) + "x" + std::to_string(height) +
                                 ", beyond --size " + std::to_string(size_));
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
        if (missing > 0)
            throw InputError("the pieces leave " + std::to_string(missing) + " of the " + std::to_string(width) + "x" +
                             std::to_string(height) + " pixels uncovered; nothing written");
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
