// The device's floors: the ray–sphere ceiling, the store-only floor and the BVH walk's floor.
#include "bench/BenchParts.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/Clock.h"
#include "gpu/GpuScene.h"
#include "kernel_layout.h"
#include "ray_sphere_kernel_comp_spv.h"
#include "ray_sphere_kernel_matrix_comp_spv.h"
#include "store_kernel_comp_spv.h"
#include "bvh_walk_kernel_comp_spv.h"
#include "scene/Transform.h"
#include "vulkan/ComputeKernel.h"

namespace snell::bench {

Ceiling measureCeiling(vk::Context& context, int runs, bool quick) {
    std::vector<gpu::CeilingSphere> spheres(SNELL_CEILING_SPHERES);
    for (int k = 0; k < SNELL_CEILING_SPHERES; ++k) {
        const dvec3 centre(-1.5 + 3.0 * (k % 8) / 7.0, -1.5 + 3.0 * (k / 8) / 7.0, -4.0 - 0.01 * k);
        spheres[k].centreRadius = glm::vec4(glm::vec3(centre), 0.15f);
        Transform t;
        t.translate(centre);
        t.scale(dvec3(0.15, 0.1, 0.2));
        spheres[k].objectFromWorld = glm::mat4(t.objectFromWorld());
    }
    const std::uint32_t rays = quick ? (1u << 16) : (1u << 20);
    vk::Buffer input = context.createBufferWithData(spheres.data(), spheres.size() * sizeof spheres[0],
                                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::Buffer output = context.createBuffer(rays * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Context::Memory::Device);
    Ceiling c;
    try {
        for (int form = 0; form < 2; ++form) {
            vk::ComputeKernel kernel(context, form == 0 ? snell_ray_sphere_kernel_comp_spv : snell_ray_sphere_kernel_matrix_comp_spv,
                                     form == 0 ? sizeof snell_ray_sphere_kernel_comp_spv : sizeof snell_ray_sphere_kernel_matrix_comp_spv,
                                     2);
            const std::uint32_t groups = rays / SNELL_KERNEL_GROUP_SIZE;
            kernel.run({&input, &output}, nullptr, groups);  // warm-up (llvmpipe compiles here)
            std::vector<double> ms;
            for (int r = 0; r < runs; ++r) ms.push_back(kernel.run({&input, &output}, nullptr, groups));
            const double testsPerSecond = double(rays) * SNELL_CEILING_SPHERES / (stats(ms).median * 1e-3);
            (form == 0 ? c.centreRadius : c.matrix) = testsPerSecond;
        }
    } catch (...) {
        context.destroy(input);
        context.destroy(output);
        throw;
    }
    context.destroy(input);
    context.destroy(output);

    // The floor.
    c.floorSize = quick ? 256 : 1024;
    const std::uint32_t pixels = std::uint32_t(c.floorSize) * std::uint32_t(c.floorSize);
    vk::Buffer image = context.createBuffer(VkDeviceSize(pixels) * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Context::Memory::Device);
    try {
        vk::ComputeKernel kernel(context, snell_store_kernel_comp_spv, sizeof snell_store_kernel_comp_spv, 1);
        kernel.run({&image}, nullptr, pixels / SNELL_KERNEL_GROUP_SIZE);
        std::vector<double> ms;
        for (int r = 0; r < runs; ++r) ms.push_back(kernel.run({&image}, nullptr, pixels / SNELL_KERNEL_GROUP_SIZE));
        c.storeMs = stats(ms).median;
    } catch (...) {
        context.destroy(image);
        throw;
    }
    context.destroy(image);
    const Scene empty = parseScene("view " + std::to_string(c.floorSize) + " 0.5\nbackground 0.2 0.3 0.4\n", "empty.scn");
    RenderRequest request;
    request.width = request.height = c.floorSize;
    request.camera = Camera::fromSpec(c.floorSize, empty.halfWidth);
    ComputeRenderer renderer(context, empty, request.camera);
    renderer.render(request, false);
    std::vector<double> ms;
    for (int r = 0; r < runs; ++r) ms.push_back(renderer.render(request, false).renderMs);
    c.emptySceneMs = stats(ms).median;
    return c;
}


std::optional<WalkFloor> measureWalkFloor(vk::Context& context, const Scene& scene, const std::string& name,
                                          const RenderRequest& base, int runs) {
    RenderRequest request = base;
    request.supersample = 1;  // the kernel casts each pixel's centre
    request.trace.maxDepth = 0;
    request.trace.minWeight = 0.0;
    request.trace.tolerance = 0.0;
    const gpu::GpuScene layout = gpu::buildGpuScene(scene, request.camera);
    if (!layout.usesBvh()) return std::nullopt;
    WalkFloor w;
    w.scene = name;
    w.size = request.width;
    gpu::FrameParams frame = gpu::makeFrameParams(scene, layout, request);
    // Storage buffers may not be empty: a scene without ellipsoids or lights
    // binds one unused element.
    const std::vector<gpu::Ellipsoid> ellipsoids =
        layout.ellipsoids.empty() ? std::vector<gpu::Ellipsoid>(1) : layout.ellipsoids;
    const std::vector<gpu::Light> lights = layout.lights.empty() ? std::vector<gpu::Light>(1) : layout.lights;
    const std::uint32_t pixels = std::uint32_t(request.width) * std::uint32_t(request.height);
    constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    std::vector<vk::Buffer> buffers;
    buffers.reserve(6);  // push_back cannot throw and lose a buffer
    auto release = [&] {
        for (vk::Buffer& b : buffers) context.destroy(b);
    };
    try {
        vk::Buffer nodes = context.createBufferWithData(layout.nodes.data(), layout.nodes.size() * sizeof(gpu::BvhNode),
                                                        VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
        buffers.push_back(nodes);
        gpu::splitAddress(context.deviceAddress(nodes), frame.bvhAddressLow, frame.bvhAddressHigh);
        buffers.push_back(context.createBufferWithData(&frame, sizeof frame, storage));
        buffers.push_back(context.createBufferWithData(layout.spheres.data(), layout.spheres.size() * sizeof(gpu::Sphere), storage));
        buffers.push_back(context.createBufferWithData(ellipsoids.data(), ellipsoids.size() * sizeof(gpu::Ellipsoid), storage));
        buffers.push_back(context.createBufferWithData(lights.data(), lights.size() * sizeof(gpu::Light), storage));
        buffers.push_back(context.createBuffer(VkDeviceSize(pixels) * 4 * sizeof(std::uint32_t), storage,
                                               vk::Context::Memory::HostCached));
        const auto stackSize = std::uint32_t(layout.bvhStackSize());
        vk::ComputeKernel kernel(context, snell_bvh_walk_kernel_comp_spv, sizeof snell_bvh_walk_kernel_comp_spv, 5,
                                 0, {stackSize, stackSize <= SNELL_REGISTER_STACK_LIMIT ? 1u : 0u});
        std::vector<const vk::Buffer*> bound;  // all but the nodes
        for (std::size_t k = 1; k < buffers.size(); ++k) bound.push_back(&buffers[k]);
        // Rows of at most 32768 workgroups (a device may allow no more than
        // 65535 in one dimension).
        const std::uint32_t groups = (pixels + SNELL_KERNEL_GROUP_SIZE - 1) / SNELL_KERNEL_GROUP_SIZE;
        const std::uint32_t groupsX = std::min(groups, 32768u);
        const std::uint32_t groupsY = (groups + groupsX - 1) / groupsX;
        kernel.run(bound, nullptr, groupsX, groupsY);  // warm-up (llvmpipe compiles here)
        std::vector<double> ms;
        for (int r = 0; r < runs; ++r) ms.push_back(kernel.run(bound, nullptr, groupsX, groupsY));
        w.floorMs = stats(ms).median;
        const auto* results = static_cast<const std::uint32_t*>(buffers.back().mapped);
        w.floorRays = pixels;
        for (std::uint32_t p = 0; p < pixels; ++p) {
            w.floorHits += results[4 * p] != 0xffffffffu ? 1 : 0;
            w.floorRays += results[4 * p + 1];
            w.floorBlocked += results[4 * p + 2];
        }
    } catch (...) {
        release();
        throw;
    }
    release();
    ComputeRenderer renderer(context, scene, request.camera);
    w.renderRays = renderer.render(request, true).rays.total();
    std::vector<double> ms;
    for (int r = 0; r < runs; ++r) ms.push_back(renderer.render(request, false).renderMs);
    w.renderMs = stats(ms).median;
    return w;
}

std::string describe(const WalkFloor& w) {
    const double floorRate = double(w.floorRays) / (w.floorMs * 1e-3);
    const double renderRate = double(w.renderRays) / (w.renderMs * 1e-3);
    std::ostringstream s;
    s << "walk floor at " << w.size << "x" << w.size << ", depth 0: kernel " << number(w.floorMs) << " ms ("
      << number(floorRate * 1e-6) << " Mrays/s), renderer " << number(w.renderMs) << " ms ("
      << number(renderRate * 1e-6) << " Mrays/s, " << number(w.renderMs / w.floorMs) << "x the floor)";
    if (w.floorRays != w.renderRays) s << "; rays " << w.floorRays << " against the renderer's " << w.renderRays;
    return s.str();
}

}  // namespace snell::bench
