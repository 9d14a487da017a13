// A compute shader whose bindings are all storage buffers (binding i is the
// i-th buffer given to run()), with optional push constants: the small,
// general pipeline that tests and benchmark kernels need. The renderer's own
// pipeline (host/gpu/ComputeRenderer) has more to it.
#pragma once

#include <cstdint>
#include <vector>

#include "vulkan/VulkanContext.h"

namespace snell::vk {

class ComputeKernel {
public:
    // specialisation: the values of constant_id 0, 1, … (32-bit each: uint,
    // or bool as 0/1).
    ComputeKernel(Context& context, const std::uint32_t* spirv, std::size_t spirvBytes, std::uint32_t storageBuffers,
                  std::uint32_t pushConstantBytes = 0, const std::vector<std::uint32_t>& specialisation = {});
    ~ComputeKernel();
    ComputeKernel(const ComputeKernel&) = delete;
    ComputeKernel& operator=(const ComputeKernel&) = delete;

    // Bind the buffers, push the constants, dispatch and wait. Returns the
    // dispatch's duration in ms, from GPU timestamps when the device has them.
    double run(const std::vector<const Buffer*>& buffers, const void* pushConstants, std::uint32_t groupsX,
               std::uint32_t groupsY = 1, std::uint32_t groupsZ = 1);

private:
    void release();

    Context& context_;
    std::uint32_t storageBuffers_;
    std::uint32_t pushConstantBytes_;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkShaderModule module_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    VkDescriptorSet set_ = VK_NULL_HANDLE;
    VkQueryPool queries_ = VK_NULL_HANDLE;
};

}  // namespace snell::vk
