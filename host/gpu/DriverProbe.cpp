#include "gpu/DriverProbe.h"

#include <cstring>
#include <map>
#include <mutex>
#include <filesystem>
#include <string>
#include <vector>

#include "loop_limit_probe_comp_spv.h"  // generated at build time from shaders/loop_limit_probe.comp
#include "shared_layout.h"
#include "vulkan/ComputeKernel.h"
#include "vulkan/KeptFile.h"

namespace snell {
namespace {

constexpr std::uint32_t kFileMagic = 0x504c4e53;  // "SNLP"
constexpr std::uint32_t kFormat = 1;

// What a kept outcome is for: the probe's format and the device and driver
// (their names in full, so no other driver's outcome is ever read).
std::vector<std::uint32_t> probeHeader(const std::string& key) {
    std::vector<std::uint32_t> header{kFileMagic, kFormat, std::uint32_t(key.size())};
    for (std::size_t i = 0; i < key.size(); i += 4) {
        std::uint32_t word = 0;
        for (std::size_t k = 0; k < 4 && i + k < key.size(); ++k) word |= std::uint32_t(std::uint8_t(key[i + k])) << (8 * k);
        header.push_back(word);
    }
    return header;
}

}  // namespace

bool limitsLoopIterations(vk::Context& context) {
    if (!context.isLlvmpipe()) return false;
    static std::mutex mutex;
    static std::map<std::string, bool> probed;  // by device and driver version
    const std::string key = context.deviceName() + "|" + context.driverInfo();
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = probed.find(key); it != probed.end()) return it->second;
    // A driver's answer does not change: kept in the cache directory, the
    // probe (a pipeline and a dispatch, some 4 ms on lavapipe) runs once.
    const std::vector<std::uint32_t> header = probeHeader(key);
    vk::WordHash hash;
    hash.add(header);
    const std::string directory = context.cacheDirectory();
    const std::filesystem::path path =
        directory.empty() ? std::filesystem::path() : vk::keptPath(std::filesystem::path(directory) / "probes", hash.value(), ".probe");
    if (!path.empty()) {
        const std::vector<char> kept = vk::readKept(path, header);
        if (kept.size() == 1 && (kept[0] == '0' || kept[0] == '1')) return probed[key] = kept[0] == '1';
    }

    const std::uint32_t iterations = 2 * SNELL_DRIVER_LOOP_LIMIT;
    vk::Buffer result = context.createBuffer(sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Context::Memory::HostCached);
    std::uint32_t passes = 0;
    try {
        vk::ComputeKernel kernel(context, snell_loop_limit_probe_comp_spv, sizeof snell_loop_limit_probe_comp_spv, 1,
                                 sizeof iterations);
        kernel.run({&result}, &iterations, 1);
        std::memcpy(&passes, result.mapped, sizeof passes);
    } catch (...) {
        context.destroy(result);
        throw;
    }
    context.destroy(result);
    const bool limits = passes != iterations;
    if (!path.empty()) vk::keep(path, header, std::string(limits ? "1" : "0"), 16);
    return probed[key] = limits;
}

}  // namespace snell
