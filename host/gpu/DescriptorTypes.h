// The descriptor type of each binding of shared_layout.h.
#pragma once

#include <cstdint>

#include <vulkan/vulkan.h>

#include "shared_layout.h"

namespace snell::gpu {

inline VkDescriptorType descriptorType(std::uint32_t binding) {
    switch (binding) {
    case SNELL_BINDING_FRAME:
    case SNELL_BINDING_FRAME_LOW:
    case SNELL_BINDING_SPHERE_BLOCK: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    case SNELL_BINDING_SPHERES:
    case SNELL_BINDING_SPHERE_MATERIALS:
    case SNELL_BINDING_ELLIPSOIDS:
    case SNELL_BINDING_MATERIALS:
    case SNELL_BINDING_LIGHTS:
    case SNELL_BINDING_BVH:
    case SNELL_BINDING_REACH:
    case SNELL_BINDING_SPHERES_LOW:
    case SNELL_BINDING_ELLIPSOIDS_LOW:
    case SNELL_BINDING_LIGHTS_LOW: return VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    case SNELL_BINDING_ACCELERATION: return VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    default: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    }
}

}  // namespace snell::gpu
