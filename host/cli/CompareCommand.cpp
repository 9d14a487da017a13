// `snell compare`: error metrics of a test image against a reference, and a
// verdict for scripts and graders. Exit status as cmp(1)'s: 0 the images
// agree within the thresholds, 1 they do not (or no pixel could be compared),
// 2 trouble (an image that cannot be read or written, sizes that differ, a
// --bound-image that is not one).
#include <cstdio>
#include <iostream>

#include "cli/Command.h"
#include "cli/ExitStatus.h"
#include "cli/Options.h"
#include "image/BoundImage.h"
#include "image/ImageIO.h"
#include "metrics/ImageMetrics.h"

namespace snell::cli {
namespace {

constexpr int kExitDiffer = 1;

struct Thresholds {
    int badLevel = 3;          // a pixel is bad when a channel is off by more (1/255 units)
    double maxMean = 0.5;      // mean absolute error, 1/255 units
    double maxBad = 0.1;       // bad pixels, % of those compared
    double maxUncertain = 1.0; // pixels left out by --bound-image, % of all
};

class CompareCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override {
        CLI::App* c = app.add_subcommand(
            "compare",
            "Compare image A with reference B (8-bit units): metrics, and exit status 0 if they agree within the "
            "thresholds, 1 if not (or no pixel could be compared), 2 on trouble");
        c->add_option("a", a_, "Test image")->required();
        c->add_option("b", b_, "Reference image")->required();
        c->add_option("--diff", diff_, "Write a false-colour difference image")->check(kImageFormat);
        c->add_option("--bad-threshold", t_.badLevel, "A pixel is bad when a channel differs by more than N/255 (default 3)")
            ->check(wholeNumber(0, 255));
        c->add_option("--max-mean", t_.maxMean, "Largest mean absolute error that agrees, in 1/255 (default 0.5)")
            ->check(number(0.0));
        c->add_option("--max-bad", t_.maxBad, "Largest share of bad pixels that agrees, in percent (default 0.1)")
            ->check(number(0.0, 100.0));
        c->add_option("--bound-image", bound_,
                      "The reference's bound image (render --bound-image, .pfm or .exr). It certifies a pixel whose "
                      "bound is within half an 8-bit step: compared as usual. Where the reference has no finite bound "
                      "(ks + kt >= 1) but estimated its error, the pixel is held to that estimate: compared, bad "
                      "beyond it, and counted as estimated. Any other pixel is left out as uncertain, unless its "
                      "bound proves it wrong. A file that is not a bound image is refused")
            ->check(kExistingFile);
        c->add_option("--max-uncertain", t_.maxUncertain,
                      "Largest share of pixels --bound-image may leave out, in percent; more disagrees (default 1)")
            ->check(number(0.0, 100.0));
        c->add_flag("--json", json_, "One JSON object instead of text");
        return c;
    }

    int run() override {
        try {
            return compare();
        } catch (const std::exception& e) {  // unreadable images, sizes that differ: trouble, not a verdict
            throw InputError(e.what());
        }
    }

private:
    int compare() const {
        const Image test = readImage(a_);
        const Image reference = readImage(b_);
        BoundImage bound;
        if (!bound_.empty()) bound = readBoundImage(bound_);
        if (!bound.note.empty()) std::cerr << "snell: warning: " << bound.note << "\n";
        const ImageMetrics m = compareImages(test, reference, t_.badLevel, bound_.empty() ? nullptr : &bound);
        if (!diff_.empty()) writeImage(diff_, differenceImage(test, reference));
        const std::string verdict = judge(m);
        if (json_) {
            std::string j = m.json();
            j.pop_back();
            std::cout << j << ", \"agree\": " << (verdict.empty() ? "true" : "false") << "}" << std::endl;
        } else {
            printText(m, verdict);
        }
        return verdict.empty() ? kExitSuccess : kExitDiffer;
    }

    void printText(const ImageMetrics& m, const std::string& verdict) const {
        using ull = unsigned long long;
        if (m.pixels == 0)
            std::printf("no pixel compared, NaN/Inf %llu\n", ull(m.nonFinite));
        else
            std::printf("mean abs error %.4f/255, RMSE %.4f/255, PSNR %.2f dB, max %d/255\n"
                        "bad pixels (> %d/255) %llu of %llu (%.4f%%), isolated speckles %llu, NaN/Inf %llu\n",
                        m.meanAbsError, m.rmse, m.psnr, m.maxError, t_.badLevel, ull(m.badPixels), ull(m.pixels),
                        100.0 * m.badFraction, ull(m.speckles), ull(m.nonFinite));
        if (!bound_.empty()) {
            std::printf("held %llu of them to the reference's estimated error, as it has no finite bound there "
                        "(%llu bad)\n",
                        ull(m.estimated), ull(m.estimatedBad));
            std::printf("left out %llu uncertain pixel(s) of %llu (the reference's bound cannot decide them)\n",
                        ull(m.uncertain), ull(m.pixels + m.uncertain));
        }
        std::printf("%s\n", verdict.empty() ? "agree" : ("differ: " + verdict).c_str());
    }

    // Why the images do not agree (empty when they do).
    std::string judge(const ImageMetrics& m) const {
        char why[160];
        std::string out;
        auto add = [&out](const char* reason) { out += (out.empty() ? "" : "; ") + std::string(reason); };
        const double all = double(m.pixels + m.uncertain);
        // Comparing nothing is no agreement.
        if (m.pixels == 0) {
            std::snprintf(why, sizeof why, "no pixel compared (%llu left out as uncertain)",
                          static_cast<unsigned long long>(m.uncertain));
            add(why);
        }
        if (m.nonFinite > 0) add("the test image has NaN or infinite values");
        if (m.meanAbsError > t_.maxMean) {
            std::snprintf(why, sizeof why, "mean %.4f/255 > --max-mean %g", m.meanAbsError, t_.maxMean);
            add(why);
        }
        if (100.0 * m.badFraction > t_.maxBad) {
            std::snprintf(why, sizeof why, "bad pixels %.4f%% > --max-bad %g%%", 100.0 * m.badFraction, t_.maxBad);
            add(why);
        }
        if (all > 0 && 100.0 * m.uncertain / all > t_.maxUncertain) {
            std::snprintf(why, sizeof why, "uncertain pixels %.4f%% > --max-uncertain %g%%",
                          100.0 * m.uncertain / all, t_.maxUncertain);
            add(why);
        }
        return out;
    }

    std::string a_, b_, diff_, bound_;
    Thresholds t_;
    bool json_ = false;
};

}  // namespace

std::unique_ptr<Command> makeCompareCommand() { return std::make_unique<CompareCommand>(); }

}  // namespace snell::cli
