#include "cli/Options.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include <unistd.h>

#include "check/SceneCheck.h"
#include "cli/ExitStatus.h"
#include "gpu/ComputeRenderer.h"
#include "image/ImageIO.h"
#include "scene/Parser.h"

namespace snell::cli {

namespace {

// A bound as the messages say it: 16384, 0.5, 1e-05.
std::string bound(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

// Bounds from the width of the value's type (an int's 2147483647) go unsaid.
bool stated(double bound) { return std::isfinite(bound) && std::abs(bound) < double(std::numeric_limits<int>::max()); }

// "a whole number from 1 to 16384", "a number, 0 or more", "a finite number".
std::string rangeInWords(const std::string& kind, double lowest, double highest) {
    const bool low = stated(lowest), high = stated(highest);
    if (low && high) return kind + " from " + bound(lowest) + " to " + bound(highest);
    if (low) return kind + ", " + bound(lowest) + " or more";
    if (high) return kind + ", " + bound(highest) + " or less";
    return kind == "a number" ? std::string("a finite number") : kind;
}

// The same, as --help names the option's values: "[1 - 16384]", ">= 0".
std::string rangeName(double lowest, double highest) {
    const bool low = stated(lowest), high = stated(highest);
    if (low && high) return "[" + bound(lowest) + " - " + bound(highest) + "]";
    if (low) return ">= " + bound(lowest);
    if (high) return "<= " + bound(highest);
    return "FINITE";
}

}  // namespace

CLI::Validator wholeNumber(long long lowest, long long highest) {
    const double low = double(lowest), high = double(highest);
    const std::string words = rangeInWords("a whole number", low, high);
    return CLI::Validator(
        [=](const std::string& text) {
            errno = 0;
            char* end = nullptr;
            const long long value = std::strtoll(text.c_str(), &end, 10);
            const bool whole = !text.empty() && !std::isspace(static_cast<unsigned char>(text[0])) && *end == '\0' &&
                               errno == 0;
            if (whole && value >= lowest && value <= highest) return std::string();
            // Past a bound the words leave unsaid (or past any whole number): say it.
            const std::string limit = !stated(high) && (errno == ERANGE || (whole && value > highest))
                                          ? " (at most " + std::to_string(highest) + ")"
                                          : "";
            return "must be " + words + ", not '" + text + "'" + limit;
        },
        rangeName(low, high));
}

CLI::Validator number(double lowest, double highest) {
    const std::string words = rangeInWords("a number", lowest, highest);
    return CLI::Validator(
        [=](const std::string& text) {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            const bool read = !text.empty() && !std::isspace(static_cast<unsigned char>(text[0])) && *end == '\0';
            if (read && std::isfinite(value) && value >= lowest && value <= highest) return std::string();
            return "must be " + words + ", not '" + text + "'";
        },
        rangeName(lowest, highest));
}

const CLI::Validator kFinite = number(-INFINITY, INFINITY);

CLI::Validator oneOf(std::vector<std::string> names) {
    std::string list, name;
    for (const std::string& n : names) {
        list += (list.empty() ? "" : ", ") + n;
        name += (name.empty() ? "{" : ",") + n;
    }
    return CLI::Validator(
        [names = std::move(names), list](const std::string& text) {
            if (std::find(names.begin(), names.end(), text) != names.end()) return std::string();
            return "must be one of " + list + ", not '" + text + "'";
        },
        name + "}");
}

const CLI::Validator kExistingFile(
    [](const std::string& path) {
        std::error_code error;
        const auto status = std::filesystem::status(path, error);
        if (std::filesystem::is_directory(status)) return "'" + path + "' is a directory, not a file";
        if (!std::filesystem::exists(status)) return "no such file: '" + path + "'";
        return std::string();
    },
    "FILE");

const CLI::Validator kImageFormat(
    [](const std::string& path) {
        // gzip's rule: binary data is not for a terminal, where it would
        // scramble the screen; the render would be wasted too.
        if (path == kStandardOutput && ::isatty(STDOUT_FILENO))
            return std::string("- writes a binary PPM image to standard output, which is a terminal here: "
                               "redirect it to a file (> image.ppm) or pipe it to a program (| display)");
        try {
            formatForPath(path);
            return std::string();
        } catch (const ImageIOError& e) {
            return std::string(e.what());
        }
    },
    "IMAGE");

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
        ->check(oneOf(exrCompressionNames()));
}

namespace {
const CLI::Validator kPrecisions = oneOf({"fp32", "fp64"});
const CLI::Validator kTraversals = oneOf({"auto", "bvh", "ray-query"});
const CLI::Validator kSwitch = oneOf({"1", "0", "true", "false", "yes", "no", "on", "off"});
}  // namespace

void addDeviceOptions(CLI::App& command, DeviceOptions& o) {
    o.defined = {
        command.add_option("--gpu", o.gpu,
                           "Vulkan device index (see 'snell devices'; default: $SNELL_GPU, else the best)")
            ->check(wholeNumber(0, std::numeric_limits<int>::max())),
        command.add_option("--precision", o.precision,
                           "GPU arithmetic for geometry: fp32 (default) or fp64 (needs shaderFloat64; slower; "
                           "not on NVIDIA's driver)")
            ->check(kPrecisions),
        command.add_option("--traversal", o.traversal,
                           "How BVH scenes are searched: bvh (snell's walk), ray-query (the device's ray traversal, "
                           "VK_KHR_ray_query; fp32), or auto (ray queries on GPUs that have them, else bvh; the "
                           "default, unless $SNELL_TRAVERSAL names another)")
            ->check(kTraversals),
        command.add_flag("--validation", o.validation,
                         "Enable the Khronos validation layer (as does SNELL_VALIDATION=1); any message it reports is "
                         "an error"),
    };
}

namespace {
// A variable's value, or null where it is unset or empty.
const char* environment(const char* name) {
    const char* value = std::getenv(name);
    return value && *value ? value : nullptr;
}

// The environment's value for an option, checked as the option's own would be.
std::string checkedEnvironment(const char* name, const CLI::Validator& validator) {
    std::string value = environment(name);
    if (const std::string error = validator(value); !error.empty())
        throw InputError(std::string(name) + ": " + error);
    return value;
}
}  // namespace

int environmentGpu() {
    if (!environment("SNELL_GPU")) return -1;
    return std::stoi(checkedEnvironment("SNELL_GPU", wholeNumber(0, std::numeric_limits<int>::max())));
}

void DeviceOptions::readEnvironment() {
    auto unset = [this](const char* option) {
        return std::none_of(defined.begin(), defined.end(),
                            [&](const CLI::Option* o) { return o->check_name(option) && o->count() > 0; });
    };
    if (unset("--gpu")) gpu = environmentGpu();
    if (unset("--traversal") && environment("SNELL_TRAVERSAL"))
        traversal = checkedEnvironment("SNELL_TRAVERSAL", kTraversals);
    if (unset("--validation") && environment("SNELL_VALIDATION")) {
        const std::string value = checkedEnvironment("SNELL_VALIDATION", kSwitch);
        validation = value == "1" || value == "true" || value == "yes" || value == "on";
    }
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

std::vector<std::string> DeviceOptions::given() const {
    std::vector<std::string> names;
    for (const CLI::Option* o : defined)
        if (o->count() > 0) names.push_back(o->get_name());
    return names;
}

void addTreeOptions(CLI::App& command, TreeOptions& o, const TreeHelp& help) {
    command.add_option("-d,--depth", o.depth, help.depth)->check(wholeNumber(0, help.maxDepth));
    command.add_option("--min-weight", o.minWeight, help.minWeight)->check(number(0.0, 1.0));
    command.add_option("--spp,--supersample", o.supersample,
                       "Rays per pixel per axis (overrides the scene's supersample)")
        ->check(wholeNumber(1, ParseLimits::kMaxSupersample));
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

bool decisionsKept() {
    const char* decisions = std::getenv("SNELL_DECISIONS");
    if (!decisions || !*decisions || std::string(decisions) == "on") return true;
    if (std::string(decisions) == "off") return false;
    throw InputError(std::string("SNELL_DECISIONS: expected 'on' or 'off', not '") + decisions + "'");
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
