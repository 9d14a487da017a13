// `snell devices`: the Vulkan devices and why any cannot be used.
#include <iostream>

#include "cli/Command.h"
#include "cli/ExitStatus.h"
#include "vulkan/VulkanContext.h"

namespace snell::cli {
namespace {

// Which search of BVH scenes --traversal auto takes on the device, and why.
std::string traversal(const vk::DeviceReport& r) {
    if (!r.rayQueries) return "; traversal: bvh (no ray queries)";
    return r.type == "CPU" ? "; traversal: bvh (ray queries too: --traversal ray-query; slower here)"
                           : "; traversal: ray-query (--traversal bvh for snell's walk)";
}

// How the device's kernels start: from driver binaries kept by earlier runs, or as pipelines.
std::string kernels(const vk::DeviceReport& r) {
    return r.shaderObjects ? "; kernels: kept driver binaries (VK_EXT_shader_object)"
                           : "; kernels: pipelines (no VK_EXT_shader_object)";
}

class DevicesCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override {
        return app.add_subcommand("devices", "List the Vulkan devices and why any cannot be used");
    }

    int run() override {
        const auto reports = vk::Context::listDevices();
        if (reports.empty()) throw std::runtime_error("no Vulkan device found: apt-get install mesa-vulkan-drivers");
        for (const auto& r : reports)
            std::cout << r.index << ": " << r.name << " (" << r.type << ", " << r.driver << ")"
                      << (r.usable ? "" : " — unusable: " + r.reason)
                      << (r.usable ? traversal(r) + kernels(r) : "")
                      << (r.usable && !r.fp64Refusal.empty() ? "; no --precision fp64: " + r.fp64Refusal : "") << "\n";
        return kExitSuccess;
    }
};

}  // namespace

std::unique_ptr<Command> makeDevicesCommand() { return std::make_unique<DevicesCommand>(); }

}  // namespace snell::cli
