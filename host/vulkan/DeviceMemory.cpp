// The context's device memory: buffers (mapped where the host reads or
// writes them), images, and one-off command buffers that fill them.
#include <algorithm>
#include <cstring>

#include "vulkan/VulkanContext.h"

namespace snell::vk {

VkResult Context::allocate(const VkMemoryAllocateInfo& info, VkDeviceMemory* memory) {
    if (fault_.kind == FaultInjection::Kind::OutOfDeviceMemory && ++allocations_ == fault_.at)
        return VK_ERROR_OUT_OF_DEVICE_MEMORY;
    return vkAllocateMemory(device_, &info, nullptr, memory);
}

VkDeviceSize Context::deviceLocalBytes() const {
    VkDeviceSize largest = 0;
    for (std::uint32_t i = 0; i < memory_.memoryHeapCount; ++i)
        if (memory_.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            largest = std::max(largest, memory_.memoryHeaps[i].size);
    return largest;
}

std::uint32_t Context::findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                      VkMemoryPropertyFlags preferred) const {
    for (VkMemoryPropertyFlags want : {required | preferred, required}) {
        for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
            if ((typeBits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & want) == want) return i;
        }
    }
    throw VulkanError("no suitable Vulkan memory type for a buffer or image");
}

Buffer Context::createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, Memory memory) {
    const bool hostVisible = memory != Memory::Device;
    Buffer b;
    b.size = std::max<VkDeviceSize>(size, 16);  // zero-sized buffers are invalid in Vulkan
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = b.size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(device_, &info, nullptr, &b.buffer), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, b.buffer, &req);
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) alloc.pNext = &flags;
    alloc.allocationSize = req.size;
    try {
        alloc.memoryTypeIndex = hostVisible
            ? findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                             memory == Memory::DeviceMapped ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT
                                                            : VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
            : findMemoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        check(allocate(alloc, &b.memory), "vkAllocateMemory");
        check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
        if (hostVisible) check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    } catch (...) {
        destroy(b);
        throw;
    }
    return b;
}

Buffer Context::createBufferWithData(const void* bytes, VkDeviceSize size, VkBufferUsageFlags usage) {
    Buffer target = createBuffer(size, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, Memory::Device);
    if (size == 0) return target;
    // Device-local memory that the host can see (lavapipe, integrated GPUs, ReBAR) is written directly.
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, target.buffer, &req);
    bool direct = false;
    for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
        // findMemoryType picked the first device-local type this buffer allows.
        if ((req.memoryTypeBits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT)) {
            direct = (memory_.memoryTypes[i].propertyFlags & (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) ==
                     (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
            break;
        }
    }
    if (direct) {
        void* p = nullptr;
        check(vkMapMemory(device_, target.memory, 0, VK_WHOLE_SIZE, 0, &p), "vkMapMemory");
        std::memcpy(p, bytes, size);
        vkUnmapMemory(device_, target.memory);
        return target;
    }
    Buffer staging = createBuffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, Memory::HostCached);
    std::memcpy(staging.mapped, bytes, size);
    try {
        submitAndWait([&](VkCommandBuffer cmd) {
            VkBufferCopy region{0, 0, size};
            vkCmdCopyBuffer(cmd, staging.buffer, target.buffer, 1, &region);
        });
    } catch (...) {
        destroy(staging);
        destroy(target);
        throw;
    }
    destroy(staging);
    return target;
}

VkDeviceAddress Context::deviceAddress(const Buffer& b) const {
    VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    info.buffer = b.buffer;
    return vkGetBufferDeviceAddress(device_, &info);
}

void Context::destroy(Buffer& b) {
    if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
    if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
    b = Buffer{};
}

DeviceImage Context::createImage(std::uint32_t width, std::uint32_t height, VkFormat format,
                                  VkImageUsageFlags usage) {
    DeviceImage img;
    img.width = width;
    img.height = height;
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width, height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    try {
        check(vkCreateImage(device_, &info, nullptr, &img.image), "vkCreateImage");
        VkMemoryRequirements req;
        vkGetImageMemoryRequirements(device_, img.image, &req);
        VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = findMemoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        check(allocate(alloc, &img.memory), "vkAllocateMemory");
        check(vkBindImageMemory(device_, img.image, img.memory, 0), "vkBindImageMemory");
    } catch (...) {
        destroy(img);
        throw;
    }
    return img;
}

void Context::destroy(DeviceImage& img) {
    if (img.image) vkDestroyImage(device_, img.image, nullptr);
    if (img.memory) vkFreeMemory(device_, img.memory, nullptr);
    img = DeviceImage{};
}

VkCommandBuffer Context::beginOneOff() {
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VkCommandBuffer cmd;
    check(vkAllocateCommandBuffers(device_, &alloc, &cmd), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    const VkResult r = vkBeginCommandBuffer(cmd, &begin);
    if (r != VK_SUCCESS) vkFreeCommandBuffers(device_, pool_, 1, &cmd);
    check(r, "vkBeginCommandBuffer");
    return cmd;
}

void Context::endOneOffAndWait(VkCommandBuffer cmd) {
    VkResult r = vkEndCommandBuffer(cmd);
    if (r == VK_SUCCESS) {
        VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &cmd;
        r = this->submit(submit, fence_);
        if (r == VK_SUCCESS) {
            r = vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX);
            const VkResult reset = vkResetFences(device_, 1, &fence_);
            if (r == VK_SUCCESS) r = reset;
        }
    }
    vkFreeCommandBuffers(device_, pool_, 1, &cmd);
    check(r, "vkQueueSubmit/vkWaitForFences");
}

}  // namespace snell::vk
