// What a ray query traverses (VK_KHR_acceleration_structure): a bottom-level
// structure of axis-aligned boxes, primitive i the i-th box, in a top-level
// structure of one instance at the identity. Built on the device, once.
#pragma once

#include <cstdint>

#include "vulkan/VulkanContext.h"

namespace snell::vk {

class BoxAccelerationStructure {
public:
    // `boxes`: `count` boxes laid out as VkAabbPositionsKHR. The context must
    // have ray queries enabled (Context::rayQueriesEnabled).
    BoxAccelerationStructure(Context& context, const void* boxes, std::uint32_t count);
    ~BoxAccelerationStructure();
    BoxAccelerationStructure(const BoxAccelerationStructure&) = delete;
    BoxAccelerationStructure& operator=(const BoxAccelerationStructure&) = delete;

    // The top level, for a VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR binding.
    const VkAccelerationStructureKHR& top() const { return top_; }

private:
    VkAccelerationStructureKHR build(const VkAccelerationStructureGeometryKHR& geometry,
                                     VkAccelerationStructureTypeKHR type, std::uint32_t primitives, Buffer& storage);
    void release();

    Context& context_;
    PFN_vkGetAccelerationStructureBuildSizesKHR getBuildSizes_ = nullptr;
    PFN_vkCreateAccelerationStructureKHR create_ = nullptr;
    PFN_vkDestroyAccelerationStructureKHR destroy_ = nullptr;
    PFN_vkCmdBuildAccelerationStructuresKHR cmdBuild_ = nullptr;
    PFN_vkGetAccelerationStructureDeviceAddressKHR getAddress_ = nullptr;
    Buffer boxes_, instances_, bottomBuffer_, topBuffer_;
    VkAccelerationStructureKHR bottom_ = VK_NULL_HANDLE, top_ = VK_NULL_HANDLE;
};

}  // namespace snell::vk
