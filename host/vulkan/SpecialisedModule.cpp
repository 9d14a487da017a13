#include "vulkan/SpecialisedModule.h"

#include <cstring>
#include <spirv-tools/optimizer.hpp>
#include <unordered_map>

#include "vulkan/KeptFile.h"

namespace snell::vk {
namespace {

constexpr std::uint32_t kSpirvMagic = 0x07230203;
constexpr std::uint32_t kFileMagic = 0x50534e53;  // "SNSP"
// Changes with the passes below or the file's layout: other files are not used.
constexpr std::uint32_t kFormat = 3;
// Modules kept; beyond it the oldest go (a specialisation is some 90 KiB).
constexpr std::size_t kMaxKept = 256;

// The words a kept file starts with: what it was made from (the module by its
// length and hash), checked on reading.
std::vector<std::uint32_t> headerOf(std::span<const std::uint32_t> module, std::span<const std::uint32_t> values,
                                    std::uint64_t key) {
    std::vector<std::uint32_t> header{kFileMagic, kFormat, std::uint32_t(module.size()), std::uint32_t(key),
                                      std::uint32_t(key >> 32), std::uint32_t(values.size())};
    header.insert(header.end(), values.begin(), values.end());
    return header;
}

// The constants fixed, then the branches, functions and code they make dead
// removed; nothing else is changed (the driver optimises the rest).
std::vector<std::uint32_t> fold(std::span<const std::uint32_t> module, std::span<const std::uint32_t> values) {
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> constants;
    for (std::uint32_t id = 0; id < values.size(); ++id) constants[id] = {values[id]};
    spvtools::Optimizer optimizer(SPV_ENV_VULKAN_1_2);
    optimizer.SetMessageConsumer([](spv_message_level_t, const char*, const spv_position_t&, const char*) {});
    optimizer.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(constants))
        .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
        .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
        .RegisterPass(spvtools::CreateUnifyConstantPass())
        .RegisterPass(spvtools::CreateDeadBranchElimPass())
        .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
        .RegisterPass(spvtools::CreateAggressiveDCEPass())
        .RegisterPass(spvtools::CreateBlockMergePass());
    spvtools::OptimizerOptions options;
    options.set_run_validator(false);  // snell's own module, validated when it was built
    std::vector<std::uint32_t> folded;
    if (!optimizer.Run(module.data(), module.size(), &folded, options) || folded.empty() || folded[0] != kSpirvMagic)
        return {};
    return folded;
}

}  // namespace

std::vector<std::uint32_t> specialisedModule(std::span<const std::uint32_t> module,
                                             std::span<const std::uint32_t> values,
                                             const std::string& cacheDirectory) {
    if (cacheDirectory.empty()) return {};
    WordHash hash;
    hash.add(kFormat);
    hash.add(std::uint32_t(module.size()));
    hash.add(module);
    hash.add(std::uint32_t(values.size()));
    hash.add(values);
    const std::uint64_t key = hash.value();
    const std::vector<std::uint32_t> header = headerOf(module, values, key);
    const std::filesystem::path path = keptPath(std::filesystem::path(cacheDirectory) / "modules", key, ".spv");
    const std::vector<char> kept = readKept(path, header);
    if (kept.size() % 4 == 0 && kept.size() > 20) {
        std::vector<std::uint32_t> words(kept.size() / 4);
        std::memcpy(words.data(), kept.data(), kept.size());
        if (words[0] == kSpirvMagic) return words;
    }
    std::vector<std::uint32_t> folded = fold(module, values);
    if (!folded.empty())
        keep(path, header, std::span<const char>(reinterpret_cast<const char*>(folded.data()), folded.size() * 4),
             kMaxKept);
    return folded;
}

}  // namespace snell::vk
