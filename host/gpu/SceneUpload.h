// The scene's arrays on the device: each a texel buffer of RGBA32UI views
// (shared_layout.h), the small scenes' spheres again as a uniform block, and
// where the device's ray queries search them, the spheres' boxes.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "gpu/GpuScene.h"
#include "vulkan/BoxAccelerationStructure.h"
#include "vulkan/VulkanContext.h"

namespace snell::gpu {

class SceneBuffers {
public:
    // Throws vk::VulkanError where an array exceeds the device's texel-buffer limit.
    SceneBuffers(vk::Context& context, const GpuScene& layout, bool spheresInBlock);
    ~SceneBuffers();
    SceneBuffers(const SceneBuffers&) = delete;
    SceneBuffers& operator=(const SceneBuffers&) = delete;

    // By binding (shared_layout.h); the others stay empty.
    const vk::Buffer& buffer(std::uint32_t binding) const { return buffers_[binding]; }
    const VkBufferView* view(std::uint32_t binding) const { return &views_[binding]; }
    // The ray-query traversal's, else null.
    const vk::BoxAccelerationStructure* sphereBoxes() const { return sphereBoxes_.get(); }

private:
    void upload(std::uint32_t binding, const void* data, std::size_t bytes, const char* what,
                VkBufferUsageFlags alsoAs = 0);
    void destroy();

    vk::Context& context_;
    std::array<vk::Buffer, SNELL_BINDING_COUNT> buffers_{};
    std::array<VkBufferView, SNELL_BINDING_COUNT> views_{};
    std::unique_ptr<vk::BoxAccelerationStructure> sphereBoxes_;
};

}  // namespace snell::gpu
