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

#include "temporary_directory.h"
#include "vulkan/VulkanContext.h"

namespace snell::testing {


inline vk::Context& gpuContext() {
    // A cache directory of the test executable's own: the kernels are
    // specialised as a render with a cache specialises them
    // (vulkan/SpecialisedModule.h).
    static TemporaryDirectory cache;
    static std::unique_ptr<vk::Context> context = [] {
        vk::ContextOptions options;
        if (!cache.path().empty()) options.pipelineCachePath = cache.path() + "/pipelines.bin";
        const char* validation = std::getenv("SNELL_VALIDATION");
        options.validation = validation && std::string(validation) == "1";
        options.rayQueries = vk::RayQueries::On;
        return std::make_unique<vk::Context>(options);
    }();
    return *context;
}

}  // namespace snell::testing
