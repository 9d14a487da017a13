#include "vulkan/ComputeKernel.h"

#include <chrono>

namespace snell::vk {

ComputeKernel::ComputeKernel(Context& context, const std::uint32_t* spirv, std::size_t spirvBytes,
                             std::uint32_t storageBuffers, std::uint32_t pushConstantBytes,
                             const std::vector<std::uint32_t>& specialisation)
    : context_(context), storageBuffers_(storageBuffers), pushConstantBytes_(pushConstantBytes) {
    VkDevice device = context.device();
    try {
        std::vector<VkDescriptorSetLayoutBinding> bindings(storageBuffers);
        for (std::uint32_t i = 0; i < storageBuffers; ++i)
            bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
        VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        setInfo.bindingCount = storageBuffers;
        setInfo.pBindings = bindings.data();
        check(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout_), "vkCreateDescriptorSetLayout");
        VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
        VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        layoutInfo.setLayoutCount = 1;
        layoutInfo.pSetLayouts = &setLayout_;
        layoutInfo.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
        layoutInfo.pPushConstantRanges = &push;
        check(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout_), "vkCreatePipelineLayout");
        VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        moduleInfo.codeSize = spirvBytes;
        moduleInfo.pCode = spirv;
        check(vkCreateShaderModule(device, &moduleInfo, nullptr, &module_), "vkCreateShaderModule");
        VkComputePipelineCreateInfo pipelineInfo{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
        pipelineInfo.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        pipelineInfo.stage.module = module_;
        pipelineInfo.stage.pName = "main";
        std::vector<VkSpecializationMapEntry> entries(specialisation.size());
        for (std::uint32_t i = 0; i < entries.size(); ++i)
            entries[i] = {i, std::uint32_t(i * sizeof(std::uint32_t)), sizeof(std::uint32_t)};
        VkSpecializationInfo specialisationInfo{std::uint32_t(entries.size()), entries.data(),
                                                specialisation.size() * sizeof(std::uint32_t), specialisation.data()};
        if (!specialisation.empty()) pipelineInfo.stage.pSpecializationInfo = &specialisationInfo;
        pipelineInfo.layout = layout_;
        check(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &pipelineInfo, nullptr, &pipeline_),
              "vkCreateComputePipelines");
        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storageBuffers};
        VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        poolInfo.maxSets = 1;
        poolInfo.poolSizeCount = 1;
        poolInfo.pPoolSizes = &size;
        check(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool_), "vkCreateDescriptorPool");
        VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        alloc.descriptorPool = pool_;
        alloc.descriptorSetCount = 1;
        alloc.pSetLayouts = &setLayout_;
        check(vkAllocateDescriptorSets(device, &alloc, &set_), "vkAllocateDescriptorSets");
        if (context.timestampsSupported()) {
            VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
            q.queryType = VK_QUERY_TYPE_TIMESTAMP;
            q.queryCount = 2;
            check(vkCreateQueryPool(device, &q, nullptr, &queries_), "vkCreateQueryPool");
        }
    } catch (...) {
        release();
        throw;
    }
}

ComputeKernel::~ComputeKernel() { release(); }

void ComputeKernel::release() {
    VkDevice device = context_.device();
    if (queries_) vkDestroyQueryPool(device, queries_, nullptr);
    if (pool_) vkDestroyDescriptorPool(device, pool_, nullptr);
    if (pipeline_) vkDestroyPipeline(device, pipeline_, nullptr);
    if (module_) vkDestroyShaderModule(device, module_, nullptr);
    if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
    if (setLayout_) vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
    queries_ = VK_NULL_HANDLE;
    pool_ = VK_NULL_HANDLE;
    pipeline_ = VK_NULL_HANDLE;
    module_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    setLayout_ = VK_NULL_HANDLE;
}

double ComputeKernel::run(const std::vector<const Buffer*>& buffers, const void* pushConstants, std::uint32_t groupsX,
                          std::uint32_t groupsY, std::uint32_t groupsZ) {
    if (buffers.size() != storageBuffers_)
        throw VulkanError("internal error: a compute kernel was given the wrong number of buffers");
    std::vector<VkDescriptorBufferInfo> infos(buffers.size());
    std::vector<VkWriteDescriptorSet> writes(buffers.size());
    for (std::size_t i = 0; i < buffers.size(); ++i) {
        infos[i] = {buffers[i]->buffer, 0, VK_WHOLE_SIZE};
        writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstSet = set_;
        writes[i].dstBinding = static_cast<std::uint32_t>(i);
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(context_.device(), static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
    const auto start = std::chrono::steady_clock::now();
    context_.submitAndWait([&](VkCommandBuffer cmd) {
        if (queries_) {
            vkCmdResetQueryPool(cmd, queries_, 0, 2);
            vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 0);
        }
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
        if (pushConstantBytes_)
            vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes_, pushConstants);
        vkCmdDispatch(cmd, groupsX, groupsY, groupsZ);
        if (queries_) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, 1);
        VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        toHost.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0,
                             nullptr, 0, nullptr);
    });
    const double hostMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!queries_) return hostMs;
    std::uint64_t stamps[2] = {0, 0};
    check(vkGetQueryPoolResults(context_.device(), queries_, 0, 2, sizeof stamps, stamps, sizeof(std::uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    return double(stamps[1] - stamps[0]) * context_.properties().limits.timestampPeriod * 1e-6;
}

}  // namespace snell::vk
