#include "vulkan/BoxAccelerationStructure.h"

#include <algorithm>
#include <cstring>


namespace snell::vk {

namespace {

template <typename F>
F deviceFunction(VkDevice device, const char* name) {
    auto f = reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
    if (!f) throw VulkanError(std::string("the driver has no ") + name + " though it lists its extension");
    return f;
}

constexpr VkBufferUsageFlags kBuildInput =
    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

}  // namespace

BoxAccelerationStructure::BoxAccelerationStructure(Context& context, const void* boxes, std::uint32_t count)
    : context_(context) {
    if (!context.rayQueriesEnabled())
        throw VulkanError("internal error: an acceleration structure on a device without ray queries");
    VkDevice device = context.device();
    getBuildSizes_ = deviceFunction<PFN_vkGetAccelerationStructureBuildSizesKHR>(
        device, "vkGetAccelerationStructureBuildSizesKHR");
    create_ = deviceFunction<PFN_vkCreateAccelerationStructureKHR>(device, "vkCreateAccelerationStructureKHR");
    destroy_ = deviceFunction<PFN_vkDestroyAccelerationStructureKHR>(device, "vkDestroyAccelerationStructureKHR");
    cmdBuild_ = deviceFunction<PFN_vkCmdBuildAccelerationStructuresKHR>(device, "vkCmdBuildAccelerationStructuresKHR");
    getAddress_ = deviceFunction<PFN_vkGetAccelerationStructureDeviceAddressKHR>(
        device, "vkGetAccelerationStructureDeviceAddressKHR");
    try {
        // The boxes: one geometry; every candidate goes to the shader's own test.
        boxes_ = context.createBufferWithData(boxes, VkDeviceSize(count) * sizeof(VkAabbPositionsKHR), kBuildInput);
        VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
        geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
        geometry.geometry.aabbs = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR};
        geometry.geometry.aabbs.data.deviceAddress = context.deviceAddress(boxes_);
        geometry.geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
        bottom_ = build(geometry, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, count, bottomBuffer_);

        // One instance of it, where it is.
        VkAccelerationStructureDeviceAddressInfoKHR addressInfo{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
        addressInfo.accelerationStructure = bottom_;
        VkAccelerationStructureInstanceKHR instance{};
        instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
        instance.mask = 0xff;
        instance.accelerationStructureReference = getAddress_(device, &addressInfo);
        instances_ = context.createBufferWithData(&instance, sizeof instance, kBuildInput);
        VkAccelerationStructureGeometryKHR top{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
        top.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
        top.geometry.instances = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
        top.geometry.instances.data.deviceAddress = context.deviceAddress(instances_);
        top_ = build(top, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, 1, topBuffer_);
    } catch (...) {
        release();
        throw;
    }
    // The inputs are read by the builds alone.
    context.destroy(boxes_);
    context.destroy(instances_);
}

// Sizes, storage and a build of one level, waited for.
VkAccelerationStructureKHR BoxAccelerationStructure::build(const VkAccelerationStructureGeometryKHR& geometry,
                                                           VkAccelerationStructureTypeKHR type,
                                                           std::uint32_t primitives, Buffer& storage) {
    VkDevice device = context_.device();
    VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    info.type = type;
    info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.geometryCount = 1;
    info.pGeometries = &geometry;
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    getBuildSizes_(device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &primitives, &sizes);

    storage = context_.createBuffer(sizes.accelerationStructureSize,
                                    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                        VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                    Context::Memory::Device);
    VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    create.buffer = storage.buffer;
    create.size = sizes.accelerationStructureSize;
    create.type = type;
    VkAccelerationStructureKHR structure = VK_NULL_HANDLE;
    check(create_(device, &create, nullptr, &structure), "vkCreateAccelerationStructureKHR");

    // Scratch memory at the device's alignment for it.
    VkPhysicalDeviceAccelerationStructurePropertiesKHR limits{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
    VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &limits};
    vkGetPhysicalDeviceProperties2(context_.physicalDevice(), &properties);
    const VkDeviceSize align = std::max<VkDeviceSize>(1, limits.minAccelerationStructureScratchOffsetAlignment);
    Buffer scratch;
    try {
        scratch = context_.createBuffer(sizes.buildScratchSize + align,
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                        Context::Memory::Device);
        info.dstAccelerationStructure = structure;
        info.scratchData.deviceAddress = (context_.deviceAddress(scratch) + align - 1) / align * align;
        VkAccelerationStructureBuildRangeInfoKHR range{};
        range.primitiveCount = primitives;
        const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
        context_.submitAndWait([&](VkCommandBuffer cmd) {
            cmdBuild_(cmd, 1, &info, &ranges);
            // The build's writes before any later read: the next level's build or a ray query.
            VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
            barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
            barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                                 VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR |
                                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                 0, 1, &barrier, 0, nullptr, 0, nullptr);
        });
    } catch (...) {
        context_.destroy(scratch);
        destroy_(device, structure, nullptr);
        throw;
    }
    context_.destroy(scratch);
    return structure;
}

BoxAccelerationStructure::~BoxAccelerationStructure() { release(); }

void BoxAccelerationStructure::release() {
    VkDevice device = context_.device();
    if (top_) destroy_(device, top_, nullptr);
    if (bottom_) destroy_(device, bottom_, nullptr);
    top_ = bottom_ = VK_NULL_HANDLE;
    for (Buffer* b : {&boxes_, &instances_, &bottomBuffer_, &topBuffer_}) context_.destroy(*b);
}

}  // namespace snell::vk
