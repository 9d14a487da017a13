// `snell bench`: speed against error. For each scene it sweeps the
// renderer's settings (depth, weight cut-off, precision, BVH, supersampling),
// times the dispatches by GPU timestamps (median and range of several runs
// after a warm-up), measures the error against the converged CPU reference,
// and records the peers of the same run: the CPU reference itself (converged,
// and at the GPU's default settings), POV-Ray 3.7 on the shared bench scenes
// (the same tree, and its image against snell's where the models agree),
// the device's ray–sphere ceiling and store-only floor, the BVH walk's floor
// on each BVH scene (its rays walked alone, beside the renderer), and the render time
// against sphere count. It prices the default settings per scene: their
// dispatch time over that of the fastest fixed tree (tolerance 0: a weight
// cut-off 4^-k, or a depth cap without one) whose measured error is no worse,
// swept in order of growing cost and stopped where no later tree could set
// the price (an upper bound where none tried is as accurate). Writes
// bench.csv and bench.json, and with bench/summarize.py bench.md (tables)
// and bench.png (the plot); ends with a summary table, closed by the
// price's geometric mean and the worst scene.
#pragma once

#include <atomic>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace snell {

struct BenchOptions {
    std::vector<std::string> scenes;  // files or directories; empty: the default set
    bool quick = false;               // two scenes, fewer settings, smaller images (CI, a first look)
    int size = 0;                     // image side; 0: 128 (quick: 32)
    int runs = 5;                     // timed runs per setting, after one warm-up
    std::string outDir = "bench/results";
    std::string sourceDir;            // the repository (scenes/, bench/make_scaling_scene.py)
    std::string sharedDir;            // ../shared (course and bench scenes)
    std::string snellPath;            // this executable, for whole-command timings
    int gpu = -1;
    bool scaling = true;              // the render time against sphere count, 10 to 10^6 spheres
    const std::atomic<bool>* cancel = nullptr;
};

class BenchError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Runs the benchmark, logging progress to `log`, and ends with a table of
// the results on `summary`. Throws BenchError, vk::VulkanError, ParseError
// (a scene of the set), ImageIOError.
void runBench(const BenchOptions& options, std::ostream& log, std::ostream& summary);

}  // namespace snell
