// The Vulkan context shared by the GPU tests of one test executable. No device
// is a failure, never a skip; with SNELL_VALIDATION=1 the Khronos validation
// layer watches every test. Ray queries are enabled where the device has them
// (renderers still walk snell's BVH on lavapipe unless asked otherwise).
#pragma once

#include <stdlib.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "vulkan/VulkanContext.h"

namespace snell::testing {

// A cache directory of the test executable's own, removed at its end: the
// kernels are specialised as a render with a cache specialises them
// (vulkan/SpecialisedModule.h).
struct TemporaryCache {
    std::string directory;
    TemporaryCache() {
        char name[] = "/tmp/snell-test-cache-XXXXXX";
        if (::mkdtemp(name)) directory = name;
    }
    ~TemporaryCache() {
        std::error_code ignored;
        if (!directory.empty()) std::filesystem::remove_all(directory, ignored);
    }
};

inline vk::Context& gpuContext() {
    static TemporaryCache cache;
    static std::unique_ptr<vk::Context> context = [] {
        vk::ContextOptions options;
        if (!cache.directory.empty()) options.pipelineCachePath = cache.directory + "/pipelines.bin";
        const char* validation = std::getenv("SNELL_VALIDATION");
        options.validation = validation && std::string(validation) == "1";
        options.rayQueries = vk::RayQueries::On;
        return std::make_unique<vk::Context>(options);
    }();
    return *context;
}

}  // namespace snell::testing
