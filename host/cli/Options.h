// Option groups and inputs shared by snell's subcommands, defined once.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "gpu/GpuScene.h"
#include "image/ImageIO.h"
#include "scene/Parser.h"
#include "scene/Scene.h"
#include "vulkan/VulkanContext.h"

namespace snell::cli {

// The output's format comes from its extension; an unknown one is a
// command-line error, and so is - (a binary image on standard output) where
// standard output is a terminal.
extern const CLI::Validator kImageFormat;

// Numbers, their range said in words ("must be a whole number from 1 to
// 16384, not 'abc'", "must be a number, 0 or more"). CLI11's Range writes
// DBL_MAX in 300 digits, calls a word a value out of range and lets NaN
// through; these take no NaN or infinity.
CLI::Validator wholeNumber(long long lowest, long long highest = std::numeric_limits<long long>::max());
CLI::Validator number(double lowest, double highest = std::numeric_limits<double>::infinity());
// Any finite number.
extern const CLI::Validator kFinite;
// One of `names` ("must be one of fp32, fp64, not 'fp16'").
CLI::Validator oneOf(std::vector<std::string> names);
// A file that exists and is not a directory.
extern const CLI::Validator kExistingFile;

// --exr-compression: how an EXR output is compressed (lossless; see ExrCompression).
struct EncodingOptions {
    std::string exrCompression = exrCompressionName(kDefaultExrCompression);
    ExrCompression exr() const { return exrCompressionNamed(exrCompression); }
};
void addEncodingOptions(CLI::App& command, EncodingOptions& options);

// Which Vulkan device renders, and how: --gpu, --precision, --traversal,
// --validation. $SNELL_GPU, $SNELL_TRAVERSAL and $SNELL_VALIDATION stand for
// the options not given, read by readEnvironment() after parsing (not by
// CLI11, which mixes them with the command line's): a render with --cpu
// refuses these options, not a standing preference of the environment.
struct DeviceOptions {
    int gpu = -1;
    std::string precision = "fp32";
    std::string traversal = "auto";
    bool validation = false;
    std::vector<const CLI::Option*> defined;  // addDeviceOptions' options
    // Where the command line left them unset, the environment's values.
    // Throws InputError, naming the variable, on a malformed value.
    void readEnvironment();
    // The options given on the command line, as it names them ("--gpu").
    std::vector<std::string> given() const;
    gpu::Precision arithmetic() const { return precision == "fp64" ? gpu::Precision::Fp64 : gpu::Precision::Fp32; }
    gpu::Traversal search() const {
        return traversal == "ray-query" ? gpu::Traversal::RayQuery
               : traversal == "bvh"     ? gpu::Traversal::Walk
                                        : gpu::Traversal::Auto;
    }
    // The context these options ask for (ray queries enabled as --traversal needs).
    vk::ContextOptions context() const;
};
void addDeviceOptions(CLI::App& command, DeviceOptions& options);
// $SNELL_GPU as a device index, -1 where it is unset; InputError where malformed.
int environmentGpu();

// The ray tree a pixel traces: --depth, --min-weight, --spp. The defaults
// differ between commands, so each says its own in the help.
struct TreeOptions {
    std::optional<int> depth;
    std::optional<double> minWeight;
    std::optional<int> supersample;
};
struct TreeHelp {
    std::string depth, minWeight;
    int maxDepth;
};
void addTreeOptions(CLI::App& command, TreeOptions& options, const TreeHelp& help);

// The scene argument: a file, or - for standard input (named <stdin> in
// messages; its default output is stdin.png), read as a stream in bounded
// memory. parseSceneArgument returns its errors; readScene throws them as a
// ParseError, with the warnings of the lines that parsed where `withWarnings`.
ParseOutcome parseSceneArgument(const std::string& argument);
Scene readScene(const std::string& argument, bool withWarnings = true);
// The scene argument as messages name it.
inline std::string sceneFile(const std::string& argument) { return argument == "-" ? "<stdin>" : argument; }
// Help text of a scene argument.
inline constexpr const char* kSceneHelp = "Scene file; - reads it from standard input";

// Compiled pipelines persist here between runs, and beside them the kernels
// with their specialisation folded in (vulkan/SpecialisedModule.h): $SNELL_CACHE_DIR, else
// $XDG_CACHE_HOME/snell, else ~/.cache/snell; empty (no cache) if none is set.
std::string pipelineCachePath();

// Testing hooks (docs/testing.md, "Faults and limits"), read from the
// environment; a malformed value is an InputError. $SNELL_INJECT_FAULT
// simulates a failing GPU; $SNELL_LOOP_BUDGET runs the shader's
// suspend-and-resume path with that loop budget (0: unset).
vk::FaultInjection faultInjection();
std::uint32_t loopBudgetOverride();
// False where SNELL_DECISIONS=off asks for a kernel that keeps no rounding
// margins (measuring what they cost: docs/decisions.md).
bool decisionsKept();

}  // namespace snell::cli
