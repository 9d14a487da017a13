#include "gpu/SceneUpload.h"

#include <algorithm>
#include <string>
#include <vector>

namespace snell::gpu {

using vk::check;

namespace {
template <typename T>
std::size_t bytesOf(const std::vector<T>& v) { return v.size() * sizeof(v[0]); }
}  // namespace

// Each scene array becomes a texel buffer (shared_layout.h): its structs
// are runs of texels, every view RGBA32UI, floats by their bits (lavapipe
// compiles its fetch functions for each new format a view has).
void SceneBuffers::upload(std::uint32_t binding, const void* data, std::size_t bytes, const char* what,
                          VkBufferUsageFlags alsoAs) {
    const VkDeviceSize maxTexels = context_.properties().limits.maxTexelBufferElements;
    const VkDeviceSize texelBytes = 16;
    if (bytes / texelBytes > maxTexels)
        throw vk::VulkanError(std::string("the scene's ") + what + " need " + std::to_string(bytes / texelBytes) +
                              " texels, more than this device's texel-buffer limit of " + std::to_string(maxTexels));
    buffers_[binding] = context_.createBufferWithData(data, bytes, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | alsoAs);
    VkBufferViewCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    info.buffer = buffers_[binding].buffer;
    info.format = VK_FORMAT_R32G32B32A32_UINT;
    info.range = VK_WHOLE_SIZE;
    check(vkCreateBufferView(context_.device(), &info, nullptr, &views_[binding]), "vkCreateBufferView");
}

SceneBuffers::SceneBuffers(vk::Context& context, const GpuScene& layout, bool spheresInBlock) : context_(context) {
    const bool wide = layout.precision == Precision::Fp64;
    try {
        // The spheres' materials four a texel.
        std::vector<std::uint32_t> sphereMaterials = layout.sphereMaterials;
        sphereMaterials.resize((sphereMaterials.size() + 3) / 4 * 4);
        upload(SNELL_BINDING_SPHERES, layout.spheres.data(), bytesOf(layout.spheres), "spheres");
        upload(SNELL_BINDING_SPHERE_MATERIALS, sphereMaterials.data(), bytesOf(sphereMaterials), "spheres");
        upload(SNELL_BINDING_ELLIPSOIDS, layout.ellipsoids.data(), bytesOf(layout.ellipsoids), "ellipsoids");
        upload(SNELL_BINDING_MATERIALS, layout.materials.data(), bytesOf(layout.materials), "materials");
        upload(SNELL_BINDING_LIGHTS, layout.lights.data(), bytesOf(layout.lights), "lights");
        // Read as texels, or through its device address (FrameParams.bvhAddress).
        upload(SNELL_BINDING_BVH, layout.nodes.data(), bytesOf(layout.nodes), "BVH nodes",
               VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
        // (A texel, not a device address: Mesa 22.3 took 13 ms and leaked
        // 2 MB a dispatch reading it so.)
        upload(SNELL_BINDING_REACH, layout.reach.data(), bytesOf(layout.reach), "spheres");
        if (!layout.sphereBoxes.empty())
            sphereBoxes_ = std::make_unique<vk::BoxAccelerationStructure>(
                context_, layout.sphereBoxes.data(), static_cast<std::uint32_t>(layout.sphereBoxes.size()));
        // Small scenes: the spheres again, as a uniform block (shared_layout.h);
        // for fp64 their low parts follow in the same buffer.
        std::vector<SphereBlock> blocks(2);
        if (spheresInBlock) {
            std::copy(layout.spheres.begin(), layout.spheres.end(), blocks[0].spheres);
            std::copy(layout.sphereLows.begin(), layout.sphereLows.end(), blocks[1].spheres);
        }
        const std::size_t blockBytes = (wide ? 2 : 1) * sizeof(SphereBlock);
        buffers_[SNELL_BINDING_SPHERE_BLOCK] =
            context_.createBufferWithData(blocks.data(), blockBytes, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
        if (wide) {
            upload(SNELL_BINDING_SPHERES_LOW, layout.sphereLows.data(), bytesOf(layout.sphereLows), "spheres");
            upload(SNELL_BINDING_ELLIPSOIDS_LOW, layout.ellipsoidLows.data(), bytesOf(layout.ellipsoidLows),
                   "ellipsoids");
            upload(SNELL_BINDING_LIGHTS_LOW, layout.lightLows.data(), bytesOf(layout.lightLows), "lights");
        }
    } catch (...) {
        destroy();
        throw;
    }
}

SceneBuffers::~SceneBuffers() { destroy(); }

void SceneBuffers::destroy() {
    sphereBoxes_.reset();
    for (VkBufferView& v : views_) {
        if (v) vkDestroyBufferView(context_.device(), v, nullptr);
        v = VK_NULL_HANDLE;
    }
    for (vk::Buffer& b : buffers_) context_.destroy(b);
}

}  // namespace snell::gpu
