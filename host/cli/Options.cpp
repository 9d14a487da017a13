#include "cli/Options.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "check/SceneCheck.h"
#include "cli/ExitStatus.h"
#include "gpu/ComputeRenderer.h"
#include "image/ImageIO.h"
#include "scene/Parser.h"

namespace snell::cli {

const CLI::Validator kImageFormat(
    [](const std::string& path) {
        try {
            formatForPath(path);
            return std::string();
        } catch (const ImageIOError& e) {
            return std::string(e.what());
        }
    },
    "IMAGE");

const CLI::Validator kFinite(
    [](const std::string& text) {
        const double value = std::strtod(text.c_str(), nullptr);
        return std::isfinite(value) ? std::string() : std::string("must be a finite number");
    },
    "FINITE");

namespace {
std::vector<std::string> exrCompressionNames() {
    std::vector<std::string> names;
    for (ExrCompression c : kExrCompressions) names.emplace_back(exrCompressionName(c));
    return names;
}
}  // namespace

void addEncodingOptions(CLI::App& command, EncodingOptions& o) {
    command.add_option("--exr-compression", o.exrCompression,
                       "How an .exr output is compressed, all lossless: piz (default), rle (faster on flat "
                       "images, useless on detailed ones), zip (slower), none (largest)")
        ->check(CLI::IsMember(exrCompressionNames()));
}

void addDeviceOptions(CLI::App& command, DeviceOptions& o) {
    command.add_option("--gpu", o.gpu, "Vulkan device index (see 'snell devices'; default: $SNELL_GPU, else the best)")
        ->envname("SNELL_GPU")->check(CLI::NonNegativeNumber);
    command.add_option("--precision", o.precision,
                       "GPU arithmetic for geometry: fp32 (default) or fp64 (needs shaderFloat64; slower; "
                       "not on NVIDIA's driver)")
        ->check(CLI::IsMember({"fp32", "fp64"}));
    command.add_option("--traversal", o.traversal,
                       "How BVH scenes are searched: bvh (snell's walk), ray-query (the device's ray traversal, "
                       "VK_KHR_ray_query; fp32), or auto (default: ray queries on GPUs that have them, else bvh)")
        ->envname("SNELL_TRAVERSAL")->check(CLI::IsMember({"auto", "bvh", "ray-query"}));
    command.add_flag("--validation", o.validation,
                     "Enable the Khronos validation layer; any message it reports is an error")
        ->envname("SNELL_VALIDATION");
}

vk::ContextOptions DeviceOptions::context() const {
    vk::ContextOptions options;
    options.deviceIndex = gpu;
    options.validation = validation;
    options.rayQueries = traversal == "ray-query" ? vk::RayQueries::On
                         : traversal == "bvh"     ? vk::RayQueries::Off
                                                  : vk::RayQueries::OnGpus;
    return options;
}

void addTreeOptions(CLI::App& command, TreeOptions& o, const TreeHelp& help) {
    command.add_option("-d,--depth", o.depth, help.depth)->check(CLI::Range(0, help.maxDepth));
    command.add_option("--min-weight", o.minWeight, help.minWeight)->check(kFinite)->check(CLI::Range(0.0, 1.0));
    command.add_option("--spp,--supersample", o.supersample,
                       "Rays per pixel per axis (overrides the scene's supersample)")
        ->check(CLI::Range(1, ParseLimits::kMaxSupersample));
}

ParseOutcome parseSceneArgument(const std::string& argument) {
    if (argument != "-") return parseSceneFileRecovering(argument);
    // Standard input may be a pipe, even an endless one: a stream, never seeked.
    ParseOutcome outcome = parseSceneStreamRecovering(std::cin, "<stdin>");
    outcome.scene.name = "stdin";
    return outcome;
}

Scene readScene(const std::string& argument, bool withWarnings) {
    return sceneOrErrors(parseSceneArgument(argument), sceneFile(argument), withWarnings);
}

std::string pipelineCachePath() {
    std::string dir;
    if (const char* d = std::getenv("SNELL_CACHE_DIR"); d && *d) dir = d;
    else if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) dir = std::string(x) + "/snell";
    else if (const char* h = std::getenv("HOME"); h && *h) dir = std::string(h) + "/.cache/snell";
    return dir.empty() ? std::string() : dir + "/pipelines.bin";
}

vk::FaultInjection faultInjection() {
    const char* fault = std::getenv("SNELL_INJECT_FAULT");
    if (!fault || !*fault) return {};
    try {
        return vk::parseFaultInjection(fault);
    } catch (const std::invalid_argument& e) {
        throw InputError(std::string("SNELL_INJECT_FAULT: ") + e.what());
    }
}

std::uint32_t loopBudgetOverride() {
    const char* budget = std::getenv("SNELL_LOOP_BUDGET");
    if (!budget || !*budget) return 0;
    char* end = nullptr;
    const unsigned long value = std::strtoul(budget, &end, 10);
    if (*end != '\0' || value == 0 || value > SNELL_LOOP_BUDGET_LIMITED)
        throw InputError("SNELL_LOOP_BUDGET: expected a loop budget from 1 to " +
                         std::to_string(SNELL_LOOP_BUDGET_LIMITED) + ", not '" + budget + "'");
    return static_cast<std::uint32_t>(value);
}

}  // namespace snell::cli
