// The compiled kernel (a pipeline, or a shader object where the device has
// them) with its descriptor set, command buffer and fence, and the buffers a
// render writes: kept between renders and reused while they fit.
#pragma once

#include <cstdint>
#include <vector>

#include "gpu/KernelPolicy.h"
#include "gpu/SceneUpload.h"
#include "vulkan/ShaderObject.h"
#include "vulkan/VulkanContext.h"

namespace snell::gpu {

struct Kernel {
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    vk::ComputeShader shader;  // instead of the pipeline, where the device has shader objects
    VkShaderModule module = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;
    VkCommandPool commandPool = VK_NULL_HANDLE;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    vk::Buffer frame, counters, output, slotStates, rayStack, mediaStack;
    vk::Buffer frameLow, rayStackLow;  // fp64 only
    vk::Buffer flagged;                // each pixel's FlaggedSamples, where SNELL_SPEC_BY_SAMPLE
    std::uint32_t rayEntries = 1;     // the RAY_STACK and FRONTIER specialisations: an invocation's entries
    std::uint32_t maxMedia = 1;       // the MAX_MEDIA specialisation
    bool wide = false;                // fp64: the low parts' buffers too
    bool folded = false;              // the module has the specialisation folded in (vulkan/SpecialisedModule.h)
    std::vector<std::uint32_t> bindings;  // the shader's, in order
    // What it was built for: kept between renders and reused while these match.
    Specialisation values{};
    // What its buffers hold: reused by renders that need no more (the preview
    // alternates sizes while the camera moves).
    VkDeviceSize tilePixels = 0;
    VkDeviceSize slots = 0;  // persistent invocations
};

// Which kernel to build: its precision and traversal pick the compiled
// SPIR-V, the options how the driver gets it.
struct KernelBuild {
    bool wide = false;       // fp64
    bool rayQuery = false;   // the spheres' boxes bound for the device's ray queries
    bool fold = true;        // RendererOptions::foldSpecialisation
    bool shaderObjects = true;  // RendererOptions::useShaderObjects
};

// Builds `kernel` for `values` (it holds no buffers yet).
void createKernel(vk::Context& context, const Specialisation& values, const KernelBuild& build, Kernel& kernel);
// Waits for the device, then destroys all of it, buffers too.
void destroyKernel(vk::Context& context, Kernel& kernel);
// The kernel (shader object or pipeline) and its descriptor set, into `cmd`.
void bindKernel(const vk::Context& context, VkCommandBuffer cmd, const Kernel& kernel);

// The render's buffers: grown where `invocations` or `tilePixels` need more,
// the frame's block written for `request`, and the descriptor set pointed at
// them and at the scene's.
void prepareBuffers(vk::Context& context, Kernel& kernel, const SceneBuffers& scene, FrameParams frame,
                    const FrameParams& frameLow, VkDeviceSize invocations, VkDeviceSize tilePixels);

}  // namespace snell::gpu
