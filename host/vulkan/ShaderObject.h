// Compute kernels as shader objects (VK_EXT_shader_object) whose driver
// binaries are kept between runs. At every pipeline creation lavapipe
// translates the SPIR-V to NIR and optimises it before it finds the machine
// code in Mesa's cache: 40 of bench/simple's 46 ms. A shader object made from
// the binary the driver gave out last time skips that (5 ms), and the kernel
// is the same code (docs/log/targets.md, "Start-up").
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include <vulkan/vulkan.h>

// Debian 12's Vulkan headers (1.3.239) predate VK_EXT_shader_object (1.3.246):
// what snell uses of it, as the Vulkan registry (vk.xml) defines it.
#ifndef VK_EXT_shader_object
#define VK_EXT_shader_object 1
VK_DEFINE_NON_DISPATCHABLE_HANDLE(VkShaderEXT)
#define VK_EXT_SHADER_OBJECT_EXTENSION_NAME "VK_EXT_shader_object"
typedef enum VkShaderCodeTypeEXT {
    VK_SHADER_CODE_TYPE_BINARY_EXT = 0,
    VK_SHADER_CODE_TYPE_SPIRV_EXT = 1,
} VkShaderCodeTypeEXT;
typedef VkFlags VkShaderCreateFlagsEXT;
typedef struct VkPhysicalDeviceShaderObjectFeaturesEXT {
    VkStructureType sType;
    void* pNext;
    VkBool32 shaderObject;
} VkPhysicalDeviceShaderObjectFeaturesEXT;
typedef struct VkPhysicalDeviceShaderObjectPropertiesEXT {
    VkStructureType sType;
    void* pNext;
    uint8_t shaderBinaryUUID[VK_UUID_SIZE];
    uint32_t shaderBinaryVersion;
} VkPhysicalDeviceShaderObjectPropertiesEXT;
typedef struct VkShaderCreateInfoEXT {
    VkStructureType sType;
    const void* pNext;
    VkShaderCreateFlagsEXT flags;
    VkShaderStageFlagBits stage;
    VkShaderStageFlags nextStage;
    VkShaderCodeTypeEXT codeType;
    size_t codeSize;
    const void* pCode;
    const char* pName;
    uint32_t setLayoutCount;
    const VkDescriptorSetLayout* pSetLayouts;
    uint32_t pushConstantRangeCount;
    const VkPushConstantRange* pPushConstantRanges;
    const VkSpecializationInfo* pSpecializationInfo;
} VkShaderCreateInfoEXT;
typedef VkResult(VKAPI_PTR* PFN_vkCreateShadersEXT)(VkDevice device, uint32_t createInfoCount,
                                                     const VkShaderCreateInfoEXT* pCreateInfos,
                                                     const VkAllocationCallbacks* pAllocator, VkShaderEXT* pShaders);
typedef void(VKAPI_PTR* PFN_vkDestroyShaderEXT)(VkDevice device, VkShaderEXT shader,
                                                 const VkAllocationCallbacks* pAllocator);
typedef VkResult(VKAPI_PTR* PFN_vkGetShaderBinaryDataEXT)(VkDevice device, VkShaderEXT shader, size_t* pDataSize,
                                                           void* pData);
typedef void(VKAPI_PTR* PFN_vkCmdBindShadersEXT)(VkCommandBuffer commandBuffer, uint32_t stageCount,
                                                  const VkShaderStageFlagBits* pStages, const VkShaderEXT* pShaders);
#endif
// The registry's numbers, which the names above do not carry in 1.3.239's VkStructureType and VkResult.
constexpr VkStructureType kStructureTypePhysicalDeviceShaderObjectFeatures = VkStructureType(1000482000);
constexpr VkStructureType kStructureTypePhysicalDeviceShaderObjectProperties = VkStructureType(1000482001);
constexpr VkStructureType kStructureTypeShaderCreateInfo = VkStructureType(1000482002);
constexpr VkResult kIncompatibleShaderBinary = VkResult(1000482000);

namespace snell::vk {

// A device's shader objects: whether snell uses them, and their entry points.
struct ShaderObjects {
    bool enabled = false;
    std::string absence;  // why they are not used, when they are not
    std::array<std::uint8_t, VK_UUID_SIZE> binaryUuid{};  // binaries made under another UUID or version
    std::uint32_t binaryVersion = 0;                        // are refused by the driver
    PFN_vkCreateShadersEXT create = nullptr;
    PFN_vkDestroyShaderEXT destroy = nullptr;
    PFN_vkGetShaderBinaryDataEXT binaryData = nullptr;
    PFN_vkCmdBindShadersEXT bind = nullptr;
};

struct ComputeShaderInfo {
    std::span<const std::uint32_t> spirv;
    const char* entryPoint = "main";
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    std::span<const std::uint32_t> setLayoutWords;  // the layout's bindings and types: part of what a binary is for
    VkPushConstantRange pushConstants{};
    const VkSpecializationInfo* specialisation = nullptr;
    std::span<const std::uint32_t> specialisationWords;  // its values, likewise
};

struct ComputeShader {
    VkShaderEXT shader = VK_NULL_HANDLE;
    bool fromBinary = false;  // made from a binary kept by an earlier run
};

// The compute shader `info` describes: from the binary kept for it under
// `cacheDirectory` where the driver accepts that, else from its SPIR-V, and
// then its binary is kept for the next run (best effort). Throws VulkanError
// when the shader cannot be made from SPIR-V.
ComputeShader createComputeShader(VkDevice device, const ShaderObjects& objects, const ComputeShaderInfo& info,
                                  const std::string& cacheDirectory);

}  // namespace snell::vk
