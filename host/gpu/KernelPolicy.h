// The device policy: which of the kernel's paths this device and scene take
// (the options resolved against the driver), and the specialisation constants
// a render's kernel is built with, its stacks sized to the scene.
#pragma once

#include <array>
#include <cstdint>

#include "gpu/GpuScene.h"
#include "gpu/RendererOptions.h"
#include "render/RenderRequest.h"
#include "scene/Scene.h"
#include "vulkan/VulkanContext.h"

namespace snell::gpu {

// The kernel's specialisation constants, by SNELL_SPEC_* (shared_layout.h).
using Specialisation = std::array<std::uint32_t, SNELL_SPEC_COUNT>;

// Whether the spheres are searched by the device's ray queries. Throws
// vk::VulkanError, saying what to use instead, where the device cannot
// trace as `options` ask; sets options.bvh to On for ray queries.
bool choosesRayQueries(const vk::Context& context, RendererOptions& options);

// The paths the kernel takes for one scene's layout on one device.
struct KernelPolicy {
    bool bvhWords = false;          // the walk reads nodes through their device address
    bool stacksByAddress = false;   // the ray and media stacks through their addresses
    bool stackInRegisters = false;  // the walk's stack in registers (this scene, this setting)
    bool sharesShadowRays = false;  // a subgroup's shadow rays shared out (this device, scene, setting)
    bool spheresInBlock = false;    // every sphere in the uniform block (shared_layout.h)
    bool planForCpu = false;        // invocations, frontiers and shares as for a CPU device
    bool countLanes = false;
    bool decisions = true;          // decisions keep their rounding margins (physics/margins.glsl)
    std::uint32_t loopBudget = 0;   // loop iterations before the invocations suspend, else 0
};

// Probes the driver (gpu/DriverProbe.h) where the options leave the loop budget unset.
KernelPolicy devicePolicy(vk::Context& context, const RendererOptions& options, const GpuScene& layout);

// The constants for `request`: only what the scene uses is compiled, its ray
// stack and frontier sized to the trace settings.
Specialisation specialise(const Scene& scene, const GpuScene& layout, const KernelPolicy& policy,
                          const RenderRequest& request, bool countRays);

}  // namespace snell::gpu
