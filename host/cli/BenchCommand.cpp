// `snell bench`: speed against error over a set of scenes (host/bench/).
#include <filesystem>
#include <iostream>

#include "bench/Bench.h"
#include "cli/Command.h"
#include "cli/ExitStatus.h"
#include "cli/Options.h"

namespace snell::cli {
namespace {

class BenchCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override {
        CLI::App* c = app.add_subcommand(
            "bench",
            "Speed against error: sweep settings, compare with peers, write CSV and JSON, tables and a plot "
            "(bench/summarize.py; the plot needs matplotlib), print a summary");
        c->add_option("scenes", o_.scenes,
                      "Scene files or directories (default: scenes/, scenes/hard/, the course and bench scenes)");
        c->add_flag("--quick", o_.quick,
                    "A first look in about a minute (CI): the bench scenes simple and grid (else scenes/glass and "
                    "grid) at 32x32 with their peers, fewer settings and fixed trees, scaling at 10 and 1000 spheres");
        c->add_option("-s,--size", o_.size, "Image size (default 128; quick 32)")->check(wholeNumber(8, 4096));
        c->add_option("--runs", o_.runs, "Timed runs per setting after a warm-up (at least 5)")
            ->check(wholeNumber(5, 1000));
        c->add_option("-o,--out", o_.outDir,
                      "Directory for bench.csv, bench.json, bench.md, bench.png and the peers' POV-Ray scenes "
                      "(default bench/results)");
        c->add_option("--source-dir", o_.sourceDir,
                      "The snell repository (default: . if it has scenes/, else the build's)");
        c->add_option("--shared-dir", o_.sharedDir,
                      "Where course-scenes/ and bench-scenes/ are (default SOURCE/../shared)");
        c->add_flag("--no-scaling", noScaling_,
                    "Leave out the render time against sphere count (10 to 10^6 spheres, about a minute; "
                    "quick: 10 and 10^3)");
        c->add_option("--gpu", o_.gpu, "Vulkan device index (default: $SNELL_GPU, else the best)")
            ->check(wholeNumber(0, std::numeric_limits<int>::max()));
        return c;
    }

    int run() override {
        namespace fs = std::filesystem;
        // The repository: the working directory when it has scenes/, else where snell was built from.
        if (o_.sourceDir.empty())
            o_.sourceDir = fs::exists("scenes") && fs::exists("bench") ? "." : SNELL_SOURCE_DIR;
        if (o_.sharedDir.empty()) o_.sharedDir = (fs::path(o_.sourceDir) / ".." / "shared").string();
        std::error_code ec;
        o_.snellPath = fs::read_symlink("/proc/self/exe", ec).string();
        o_.cancel = interruptFlag();
        o_.scaling = !noScaling_;
        if (o_.gpu < 0) o_.gpu = environmentGpu();
        runBench(o_, std::cerr, std::cout);
        return kExitSuccess;
    }

private:
    BenchOptions o_;
    bool noScaling_ = false;
};

}  // namespace

std::unique_ptr<Command> makeBenchCommand() { return std::make_unique<BenchCommand>(); }

}  // namespace snell::cli
