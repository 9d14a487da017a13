#include "gpu/KernelPipeline.h"

#include <algorithm>
#include <array>
#include <span>
#include <string>

#include "gpu/DescriptorTypes.h"
#include "vulkan/SpecialisedModule.h"
#include "trace_comp_spv.h"       // generated at build time from shaders/trace.comp
#include "trace_fp64_comp_spv.h"  // the same, compiled with SNELL_FP64
#include "trace_ray_query_comp_spv.h"  // the same, compiled with SNELL_RAY_QUERY

namespace snell::gpu {

using vk::check;

namespace {

// The kernel alone, for k's module, layout and specialisation: a shader
// object from its kept binary where the device has them and the run keeps a
// cache, else a pipeline.
void createShader(vk::Context& context, Kernel& k, std::span<const std::uint32_t> code, bool shaderObjects) {
    std::array<VkSpecializationMapEntry, SNELL_SPEC_COUNT> entries{};
    for (std::uint32_t i = 0; i < entries.size(); ++i)
        entries[i] = {i, i * static_cast<std::uint32_t>(sizeof(std::uint32_t)), sizeof(std::uint32_t)};
    VkSpecializationInfo spec{static_cast<std::uint32_t>(entries.size()), entries.data(),
                              k.values.size() * sizeof(std::uint32_t), k.values.data()};
    const vk::ShaderObjects& objects = context.shaderObjects();
    const std::string cacheDirectory = context.cacheDirectory();
    if (objects.enabled && shaderObjects && !cacheDirectory.empty()) {
        std::vector<std::uint32_t> layoutWords;
        for (std::uint32_t binding : k.bindings) {
            layoutWords.push_back(binding);
            layoutWords.push_back(std::uint32_t(descriptorType(binding)));
        }
        vk::ComputeShaderInfo info;
        info.spirv = code;
        info.setLayout = k.setLayout;
        info.setLayoutWords = layoutWords;
        info.pushConstants = {VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(TileParams)};
        info.specialisation = k.folded ? nullptr : &spec;
        info.specialisationWords = k.values;
        k.shader = vk::createComputeShader(context.device(), objects, info, cacheDirectory);
        return;
    }
    VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    moduleInfo.codeSize = code.size_bytes();
    moduleInfo.pCode = code.data();
    check(vkCreateShaderModule(context.device(), &moduleInfo, nullptr, &k.module), "vkCreateShaderModule");
    VkComputePipelineCreateInfo pipelineInfo{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pipelineInfo.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipelineInfo.stage.module = k.module;
    pipelineInfo.stage.pName = "main";
    pipelineInfo.stage.pSpecializationInfo = k.folded ? nullptr : &spec;
    pipelineInfo.layout = k.layout;
    check(vkCreateComputePipelines(context.device(), context.pipelineCache(), 1, &pipelineInfo, nullptr,
                                   &k.pipeline),
          "vkCreateComputePipelines");
}

// The descriptor set's layout (the fp32 shader's bindings; fp64 adds the low
// parts, ray queries the acceleration structure) and the pipeline's.
void createLayouts(VkDevice device, const KernelBuild& build, Kernel& k) {
    k.bindings.clear();
    for (std::uint32_t i = 0; i < (build.wide ? SNELL_BINDING_COUNT : SNELL_BINDING_COUNT_FP32); ++i)
        k.bindings.push_back(i);
    if (build.rayQuery) k.bindings.push_back(SNELL_BINDING_ACCELERATION);
    std::vector<VkDescriptorSetLayoutBinding> bindings(k.bindings.size());
    for (std::size_t i = 0; i < bindings.size(); ++i) {
        bindings[i].binding = k.bindings[i];
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        bindings[i].descriptorType = descriptorType(k.bindings[i]);
    }
    VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    setInfo.bindingCount = static_cast<std::uint32_t>(bindings.size());
    setInfo.pBindings = bindings.data();
    check(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &k.setLayout), "vkCreateDescriptorSetLayout");

    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(TileParams)};
    VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &k.setLayout;
    layoutInfo.pushConstantRangeCount = 1;
    layoutInfo.pPushConstantRanges = &push;
    check(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &k.layout), "vkCreatePipelineLayout");
}

// One descriptor set for the kernel's bindings.
void createDescriptorSet(VkDevice device, Kernel& k) {
    std::vector<VkDescriptorPoolSize> sizes;
    for (std::uint32_t binding : k.bindings) {
        const VkDescriptorType type = descriptorType(binding);
        auto size = std::find_if(sizes.begin(), sizes.end(), [&](const VkDescriptorPoolSize& s) { return s.type == type; });
        if (size == sizes.end()) sizes.push_back({type, 1});
        else ++size->descriptorCount;
    }
    VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    poolInfo.maxSets = 1;
    poolInfo.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
    poolInfo.pPoolSizes = sizes.data();
    check(vkCreateDescriptorPool(device, &poolInfo, nullptr, &k.pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = k.pool;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &k.setLayout;
    check(vkAllocateDescriptorSets(device, &alloc, &k.set), "vkAllocateDescriptorSets");
}

// The command buffer, its fence, and where the device has them, the timestamps' queries.
void createCommands(const vk::Context& context, Kernel& k) {
    VkDevice device = context.device();
    VkCommandPoolCreateInfo cpInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cpInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cpInfo.queueFamilyIndex = context.queueFamily();
    check(vkCreateCommandPool(device, &cpInfo, nullptr, &k.commandPool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo cbInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cbInfo.commandPool = k.commandPool;
    cbInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbInfo.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(device, &cbInfo, &k.commands), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(device, &fenceInfo, nullptr, &k.fence), "vkCreateFence");
    if (context.timestampsSupported()) {
        VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        q.queryType = VK_QUERY_TYPE_TIMESTAMP;
        q.queryCount = 2;
        check(vkCreateQueryPool(device, &q, nullptr, &k.queries), "vkCreateQueryPool");
    }
}

}  // namespace

void createKernel(vk::Context& context, const Specialisation& values, const KernelBuild& build, Kernel& k) {
    k.values = values;
    k.wide = build.wide;
    createLayouts(context.device(), build, k);
    using Words = std::span<const std::uint32_t>;
    const Words compiled = build.wide       ? Words(snell_trace_fp64_comp_spv)
                           : build.rayQuery ? Words(snell_trace_ray_query_comp_spv)
                                            : Words(snell_trace_comp_spv);
    const std::vector<std::uint32_t> folded =
        build.fold ? vk::specialisedModule(compiled, values, context.cacheDirectory()) : std::vector<std::uint32_t>();
    k.folded = !folded.empty();
    k.rayEntries = values[SNELL_SPEC_RAY_STACK] + values[SNELL_SPEC_FRONTIER];
    k.maxMedia = values[SNELL_SPEC_MAX_MEDIA];
    createShader(context, k, k.folded ? Words(folded) : compiled, build.shaderObjects);
    createDescriptorSet(context.device(), k);
    createCommands(context, k);
}

void destroyKernel(vk::Context& context, Kernel& k) {
    VkDevice device = context.device();
    vkDeviceWaitIdle(device);
    if (k.queries) vkDestroyQueryPool(device, k.queries, nullptr);
    if (k.fence) vkDestroyFence(device, k.fence, nullptr);
    if (k.commandPool) vkDestroyCommandPool(device, k.commandPool, nullptr);
    if (k.pool) vkDestroyDescriptorPool(device, k.pool, nullptr);
    if (k.pipeline) vkDestroyPipeline(device, k.pipeline, nullptr);
    if (k.shader.shader) context.shaderObjects().destroy(device, k.shader.shader, nullptr);
    if (k.module) vkDestroyShaderModule(device, k.module, nullptr);
    if (k.layout) vkDestroyPipelineLayout(device, k.layout, nullptr);
    if (k.setLayout) vkDestroyDescriptorSetLayout(device, k.setLayout, nullptr);
    for (vk::Buffer* b : {&k.frame, &k.counters, &k.output, &k.slotStates, &k.rayStack, &k.mediaStack, &k.frameLow,
                          &k.rayStackLow, &k.flagged})
        context.destroy(*b);
}

void bindKernel(const vk::Context& context, VkCommandBuffer cmd, const Kernel& k) {
    if (k.shader.shader) {
        const VkShaderStageFlagBits stage = VK_SHADER_STAGE_COMPUTE_BIT;
        context.shaderObjects().bind(cmd, 1, &stage, &k.shader.shader);
    } else {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, k.pipeline);
    }
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, k.layout, 0, 1, &k.set, 0, nullptr);
}

}  // namespace snell::gpu
