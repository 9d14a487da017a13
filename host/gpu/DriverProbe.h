// What a driver does that its reported properties do not say, found out by
// running a tiny kernel on it.
#pragma once

#include "vulkan/VulkanContext.h"

namespace snell {

// Whether the device silently ends long shader loops: Mesa's llvmpipe before
// 24 stops every loop after 65535 passes per SIMD row and dispatch
// (SNELL_DRIVER_LOOP_LIMIT). Other drivers are taken at their word. Probed once
// per device and driver version in a process; throws vk::VulkanError.
bool limitsLoopIterations(vk::Context& context);

}  // namespace snell
