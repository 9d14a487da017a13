#include "gpu/DriverProbe.h"

#include <cstring>
#include <map>
#include <mutex>
#include <string>

#include "loop_limit_probe_comp_spv.h"  // generated at build time from shaders/loop_limit_probe.comp
#include "shared_layout.h"
#include "vulkan/ComputeKernel.h"

namespace snell {

bool limitsLoopIterations(vk::Context& context) {
    if (!context.isLlvmpipe()) return false;
    static std::mutex mutex;
    static std::map<std::string, bool> probed;  // by device and driver version
    const std::string key = context.deviceName() + "|" + context.driverInfo();
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = probed.find(key); it != probed.end()) return it->second;

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
    return probed[key] = passes != iterations;
}

}  // namespace snell
