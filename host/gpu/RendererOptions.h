// How a ComputeRenderer traces: the precision and the sphere search, and the
// switches tests and measurements use to pick each of the kernel's paths.
// Unset choices are the device's (gpu/KernelPolicy.h); every path traces the
// same image.
#pragma once

#include <cstdint>
#include <optional>

#include "gpu/GpuScene.h"

namespace snell {

struct RendererOptions {
    // Fp64 needs the device's shaderFloat64 feature. Traversal::RayQuery needs
    // ray queries enabled in the context and fp32; Auto takes them for BVH
    // scenes on a GPU where enabled.
    gpu::Precision precision = gpu::Precision::Fp32;
    gpu::BvhMode bvh = gpu::BvhMode::Auto;
    gpu::Traversal traversal = gpu::Traversal::Auto;

    // Testing: suspend and resume the invocations every this many loop
    // iterations (SNELL_LOOP_BUDGET), as on a driver that limits loops; unset,
    // where the driver ends long loops (gpu/DriverProbe.h), else never.
    std::optional<std::uint32_t> loopBudget;
    // Measuring: count the lanes busy in each loop pass (GpuRenderResult::lanes; slower).
    bool countLanes = false;
    // Measuring: false keeps no rounding margins (SNELL_DECISIONS=off): no
    // pixel is found undecided, and the bound covers truncation only.
    bool decisions = true;
    // Testing: plan as for a GPU (its invocations, frontiers and shares) on a
    // CPU device, so lavapipe runs the paths a GPU takes. A fixed tree's image
    // is the same; under a tolerance the shorter frontiers may trace some
    // rays a step early, within the bounds.
    bool planAsGpu = false;
    // With false, the driver specialises the kernel as compiled; else its
    // constants are folded in first where the context keeps a cache
    // (vulkan/SpecialisedModule.h).
    bool foldSpecialisation = true;
    // Whether the BVH walk reads the nodes through their device address (else
    // as texels); unset, as the driver reads faster.
    std::optional<bool> readBvhWords;
    // Whether the ray and media stacks are read and written through their
    // device addresses (else as storage buffers); unset, as the driver does faster.
    std::optional<bool> addressStacks;
    // Whether the walk's stack may live in registers where it fits
    // (SNELL_REGISTER_STACK_LIMIT), else an array at a per-lane index; unset,
    // on CPU devices.
    std::optional<bool> stackInRegisters;
    // Whether the shadow rays of a subgroup's hits may be shared out among its
    // lanes (schedule/lights.glsl, shadeLightsShared) where the device and scene allow
    // it, or each lane walks its own in the lights' loop.
    bool shareShadowRays = true;
    // With false, the kernel is a pipeline even where the device has shader
    // objects (vulkan/ShaderObject.h).
    bool useShaderObjects = true;
};

}  // namespace snell
