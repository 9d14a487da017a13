// The buffers a render writes, and the descriptor set that points the kernel
// at them and at the scene's (KernelPipeline.h, prepareBuffers).
#include <array>
#include <vector>

#include "gpu/DescriptorTypes.h"
#include "gpu/KernelPipeline.h"

namespace snell::gpu {

using vk::check;

namespace {

constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
// The ray and media stacks, read as storage buffers or through their addresses
// (SNELL_SPEC_STACKS_BY_ADDRESS).
constexpr VkBufferUsageFlags kStack = kStorage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

// The invocations' counters, states and stacks, for `slots` invocations.
void createSlotBuffers(vk::Context& context, Kernel& k, VkDeviceSize slots, bool wide) {
    for (vk::Buffer* b : {&k.counters, &k.slotStates, &k.rayStack, &k.mediaStack, &k.rayStackLow}) context.destroy(*b);
    k.slots = slots;
    // Mapped: the host reads the invocations' progress while they run.
    // The counters device-local where they can be: every pixel taken is
    // an atomic on one, which on a discrete GPU would cross the bus.
    using Memory = vk::Context::Memory;
    k.counters = context.createBuffer(SNELL_COUNTERS_FOR(slots / SNELL_WORKGROUP_SIZE) * sizeof(std::uint32_t),
                                      kStorage, Memory::DeviceMapped);
    k.slotStates = context.createBuffer(slots * sizeof(SlotState), kStorage, Memory::HostCached);
    k.rayStack = context.createBuffer(slots * k.rayEntries * sizeof(PendingRay), kStack, Memory::Device);
    k.mediaStack = context.createBuffer(slots * k.rayEntries * k.maxMedia * 4, kStack, Memory::Device);
    if (wide) k.rayStackLow = context.createBuffer(slots * k.rayEntries * sizeof(PendingRay), kStorage, Memory::Device);
}

// The descriptor set: the render's buffers, the scene's, its views and boxes.
void writeDescriptors(const vk::Context& context, Kernel& k, const SceneBuffers& scene) {
    std::array<VkDescriptorBufferInfo, SNELL_BINDING_LIMIT> bufferInfo{};
    std::array<const vk::Buffer*, SNELL_BINDING_LIMIT> buffers{};
    buffers[SNELL_BINDING_OUTPUT] = &k.output;
    buffers[SNELL_BINDING_FRAME] = &k.frame;
    buffers[SNELL_BINDING_COUNTERS] = &k.counters;
    buffers[SNELL_BINDING_SLOT_STATES] = &k.slotStates;
    buffers[SNELL_BINDING_RAY_STACK] = &k.rayStack;
    buffers[SNELL_BINDING_MEDIA_STACK] = &k.mediaStack;
    buffers[SNELL_BINDING_FRAME_LOW] = &k.frameLow;
    buffers[SNELL_BINDING_RAY_STACK_LOW] = &k.rayStackLow;
    VkWriteDescriptorSetAccelerationStructureKHR accelerationInfo{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    std::vector<VkWriteDescriptorSet> writes(k.bindings.size());
    for (std::size_t w = 0; w < writes.size(); ++w) {
        const std::uint32_t i = k.bindings[w];
        writes[w] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[w].dstSet = k.set;
        writes[w].dstBinding = i;
        writes[w].descriptorCount = 1;
        writes[w].descriptorType = descriptorType(i);
        if (writes[w].descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER) {
            writes[w].pTexelBufferView = scene.view(i);
        } else if (writes[w].descriptorType == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) {
            accelerationInfo.accelerationStructureCount = 1;
            accelerationInfo.pAccelerationStructures = &scene.sphereBoxes()->top();
            writes[w].pNext = &accelerationInfo;
        } else {
            if (!buffers[i]) buffers[i] = &scene.buffer(i);
            bufferInfo[i] = {buffers[i]->buffer, 0, VK_WHOLE_SIZE};
            writes[w].pBufferInfo = &bufferInfo[i];
        }
    }
    vkUpdateDescriptorSets(context.device(), static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

}  // namespace

void prepareBuffers(vk::Context& context, Kernel& k, const SceneBuffers& scene, FrameParams frame,
                    const FrameParams& frameLow, VkDeviceSize invocations, VkDeviceSize tilePixels) {
    splitAddress(context.deviceAddress(scene.buffer(SNELL_BINDING_BVH)), frame.bvhAddressLow, frame.bvhAddressHigh);
    if (invocations > k.slots) createSlotBuffers(context, k, invocations, k.wide);
    splitAddress(context.deviceAddress(k.rayStack), frame.rayStackAddressLow, frame.rayStackAddressHigh);
    splitAddress(context.deviceAddress(k.mediaStack), frame.mediaStackAddressLow, frame.mediaStackAddressHigh);
    if (tilePixels > k.tilePixels) {
        context.destroy(k.output);
        k.tilePixels = tilePixels;
        // The tile's pixels, which the host reads where the shader wrote them
        // (on lavapipe, an imageStore in a loop costs 13x a buffer store).
        k.output = context.createBuffer(k.tilePixels * sizeof(OutputPixel), kStorage, vk::Context::Memory::HostCached);
        context.destroy(k.flagged);
    }
    // Each pixel's flagged samples, beside it, where the kernel keeps them
    // (SNELL_SPEC_BY_SAMPLE): written through its address, so that the other
    // kernels need no binding for it.
    if (k.values[SNELL_SPEC_BY_SAMPLE] != 0 && !k.flagged.buffer)
        k.flagged = context.createBuffer(k.tilePixels * sizeof(FlaggedSamples), kStack, vk::Context::Memory::HostCached);
    if (k.flagged.buffer) splitAddress(context.deviceAddress(k.flagged), frame.flaggedAddressLow, frame.flaggedAddressHigh);
    // The frame's block after the stacks: it holds their addresses.
    context.destroy(k.frame);
    context.destroy(k.frameLow);
    k.frame = context.createBufferWithData(&frame, sizeof frame, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    if (k.wide) k.frameLow = context.createBufferWithData(&frameLow, sizeof frameLow, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    writeDescriptors(context, k, scene);
}

}  // namespace snell::gpu
