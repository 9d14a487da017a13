#include "vulkan/ShaderObject.h"

#include <vector>

#include "vulkan/KeptFile.h"
#include "vulkan/VulkanContext.h"

namespace snell::vk {
namespace {

constexpr std::uint32_t kFileMagic = 0x42534e53;  // "SNSB"
constexpr std::uint32_t kFormat = 1;
// Binaries kept; beyond it the oldest go (lavapipe's are some 50 KiB).
constexpr std::size_t kMaxKept = 256;

// What a kept binary was made for: the SPIR-V (its length and hash), the
// layout, push constants and specialisation, and the driver's binary UUID
// and version. Checked on reading.
std::vector<std::uint32_t> headerOf(const ShaderObjects& objects, const ComputeShaderInfo& info, std::uint64_t& key) {
    std::vector<std::uint32_t> what{std::uint32_t(info.spirv.size())};
    for (std::size_t i = 0; i < VK_UUID_SIZE; i += 4)
        what.push_back(std::uint32_t(objects.binaryUuid[i]) | std::uint32_t(objects.binaryUuid[i + 1]) << 8 |
                       std::uint32_t(objects.binaryUuid[i + 2]) << 16 | std::uint32_t(objects.binaryUuid[i + 3]) << 24);
    what.push_back(objects.binaryVersion);
    what.push_back(info.pushConstants.offset);
    what.push_back(info.pushConstants.size);
    what.push_back(std::uint32_t(info.setLayoutWords.size()));
    what.insert(what.end(), info.setLayoutWords.begin(), info.setLayoutWords.end());
    what.push_back(info.specialisation ? std::uint32_t(info.specialisationWords.size()) : 0u);
    if (info.specialisation) what.insert(what.end(), info.specialisationWords.begin(), info.specialisationWords.end());
    WordHash hash;
    hash.add(kFormat);
    hash.add(what);
    hash.add(info.spirv);
    key = hash.value();
    std::vector<std::uint32_t> header{kFileMagic, kFormat, std::uint32_t(key), std::uint32_t(key >> 32)};
    header.insert(header.end(), what.begin(), what.end());
    return header;
}

}  // namespace

ComputeShader createComputeShader(VkDevice device, const ShaderObjects& objects, const ComputeShaderInfo& info,
                                  const std::string& cacheDirectory) {
    VkShaderCreateInfoEXT create{kStructureTypeShaderCreateInfo};
    create.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    create.pName = info.entryPoint;
    create.setLayoutCount = 1;
    create.pSetLayouts = &info.setLayout;
    create.pushConstantRangeCount = info.pushConstants.size ? 1 : 0;
    create.pPushConstantRanges = &info.pushConstants;
    create.pSpecializationInfo = info.specialisation;

    std::uint64_t key = 0;
    const std::vector<std::uint32_t> header = headerOf(objects, info, key);
    const std::filesystem::path path =
        cacheDirectory.empty() ? std::filesystem::path()
                               : keptPath(std::filesystem::path(cacheDirectory) / "shaders", key, ".bin");
    ComputeShader result;
    if (!path.empty()) {
        const std::vector<char> binary = readKept(path, header);
        if (!binary.empty()) {
            create.codeType = VK_SHADER_CODE_TYPE_BINARY_EXT;
            create.codeSize = binary.size();
            create.pCode = binary.data();
            // A binary the driver refuses (another build of it) is made again from the SPIR-V.
            if (objects.create(device, 1, &create, nullptr, &result.shader) == VK_SUCCESS && result.shader) {
                result.fromBinary = true;
                return result;
            }
            result.shader = VK_NULL_HANDLE;
        }
    }
    create.codeType = VK_SHADER_CODE_TYPE_SPIRV_EXT;
    create.codeSize = info.spirv.size_bytes();
    create.pCode = info.spirv.data();
    check(objects.create(device, 1, &create, nullptr, &result.shader), "vkCreateShadersEXT");
    if (path.empty()) return result;
    std::size_t size = 0;
    if (objects.binaryData(device, result.shader, &size, nullptr) != VK_SUCCESS || size == 0) return result;
    std::vector<char> binary(size);
    if (objects.binaryData(device, result.shader, &size, binary.data()) != VK_SUCCESS) return result;
    binary.resize(size);
    keep(path, header, binary, kMaxKept);
    return result;
}

}  // namespace snell::vk
