#include "vulkan/SpecialisedModule.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <spirv-tools/optimizer.hpp>
#include <unordered_map>

namespace snell::vk {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kSpirvMagic = 0x07230203;
constexpr std::uint32_t kFileMagic = 0x50534e53;  // "SNSP"
// Changes with the passes below: a file made by other passes is not used.
constexpr std::uint32_t kFormat = 2;
// Modules kept; beyond it the oldest go (a specialisation is some 90 KiB).
constexpr std::size_t kMaxKept = 256;

// FNV-1a, 64-bit, over the words that decide the result.
std::uint64_t keyOf(std::span<const std::uint32_t> module, std::span<const std::uint32_t> values) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    auto add = [&](std::uint32_t word) {
        for (int i = 0; i < 4; ++i) {
            h ^= (word >> (8 * i)) & 0xffu;
            h *= 0x100000001b3ull;
        }
    };
    add(kFormat);
    add(std::uint32_t(module.size()));
    for (std::uint32_t w : module) add(w);
    add(std::uint32_t(values.size()));
    for (std::uint32_t v : values) add(v);
    return h;
}

// The words a kept file starts with: what it was made from, checked on
// reading (a hash alone could collide). The module's length follows them.
std::vector<std::uint32_t> headerOf(std::span<const std::uint32_t> module, std::span<const std::uint32_t> values,
                                    std::uint64_t key) {
    std::vector<std::uint32_t> header{kFileMagic, kFormat, std::uint32_t(module.size()), std::uint32_t(key),
                                      std::uint32_t(key >> 32), std::uint32_t(values.size())};
    header.insert(header.end(), values.begin(), values.end());
    return header;
}

std::vector<std::uint32_t> readKept(const fs::path& path, const std::vector<std::uint32_t>& header) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return {};
    const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::size_t words = bytes.size() / 4;
    if (bytes.size() % 4 != 0 || words <= header.size() + 6) return {};
    std::vector<std::uint32_t> all(words);
    std::memcpy(all.data(), bytes.data(), bytes.size());
    const std::size_t start = header.size() + 1;  // after the module's length
    if (!std::equal(header.begin(), header.end(), all.begin()) || all[header.size()] != words - start ||
        all[start] != kSpirvMagic)
        return {};  // another module's, or cut short
    return {all.begin() + std::ptrdiff_t(start), all.end()};
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

// Best effort: written under a temporary name and renamed (concurrent runs
// never see half a file); the oldest modules go beyond kMaxKept.
void keep(const fs::path& directory, const fs::path& path, const std::vector<std::uint32_t>& header,
          const std::vector<std::uint32_t>& folded) {
    std::error_code ignored;
    fs::create_directories(directory, ignored);
    const fs::path temporary = path.string() + ".tmp-" + std::to_string(::getpid());
    {
        std::ofstream out(temporary, std::ios::binary);
        const std::uint32_t length = std::uint32_t(folded.size());
        out.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size() * 4));
        out.write(reinterpret_cast<const char*>(&length), sizeof length);
        out.write(reinterpret_cast<const char*>(folded.data()), std::streamsize(folded.size() * 4));
        if (!out) {
            fs::remove(temporary, ignored);
            return;
        }
    }
    fs::rename(temporary, path, ignored);
    if (ignored) fs::remove(temporary, ignored);

    std::vector<std::pair<fs::file_time_type, fs::path>> kept;
    for (const fs::directory_entry& e : fs::directory_iterator(directory, ignored))
        if (e.path().extension() == ".spv") kept.emplace_back(e.last_write_time(ignored), e.path());
    if (kept.size() <= kMaxKept) return;
    std::sort(kept.begin(), kept.end());
    for (std::size_t i = 0; i + kMaxKept < kept.size(); ++i) fs::remove(kept[i].second, ignored);
}

}  // namespace

std::vector<std::uint32_t> specialisedModule(std::span<const std::uint32_t> module,
                                             std::span<const std::uint32_t> values,
                                             const std::string& cacheDirectory) {
    if (cacheDirectory.empty()) return {};
    const std::uint64_t key = keyOf(module, values);
    const std::vector<std::uint32_t> header = headerOf(module, values, key);
    const fs::path directory = fs::path(cacheDirectory) / "modules";
    char name[32];
    std::snprintf(name, sizeof name, "%016llx.spv", static_cast<unsigned long long>(key));
    const fs::path path = directory / name;
    if (std::vector<std::uint32_t> kept = readKept(path, header); !kept.empty()) return kept;
    std::vector<std::uint32_t> folded = fold(module, values);
    if (!folded.empty()) keep(directory, path, header, folded);
    return folded;
}

}  // namespace snell::vk
