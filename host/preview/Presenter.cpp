#include "preview/Presenter.h"

#include <algorithm>
#include <cstring>
#include <string>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

namespace snell {

using vk::check;

namespace {

// Every transition here is between transfers.
void barrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess,
             VkAccessFlags dstAccess) {
    vk::imageBarrier(cmd, image, from, to, srcAccess, dstAccess, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_PIPELINE_STAGE_TRANSFER_BIT);
}

bool blitSupported(VkPhysicalDevice device, VkFormat format, VkFormatFeatureFlags feature) {
    VkFormatProperties p;
    vkGetPhysicalDeviceFormatProperties(device, format, &p);
    return (p.optimalTilingFeatures & feature) == feature;
}

}  // namespace

Presenter::Presenter(vk::Context& context, GLFWwindow* window) : context_(context), window_(window) {
    check(glfwCreateWindowSurface(context.instance(), window, nullptr, &surface_), "glfwCreateWindowSurface");
    try {
        VkBool32 supported = VK_FALSE;
        check(vkGetPhysicalDeviceSurfaceSupportKHR(context.physicalDevice(), context.queueFamily(), surface_,
                                                   &supported),
              "vkGetPhysicalDeviceSurfaceSupportKHR");
        if (!supported)
            throw vk::VulkanError(context.deviceName() + " cannot present to this window from its compute queue; "
                                  "try another device with --gpu");
        if (!blitSupported(context.physicalDevice(), VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_FEATURE_BLIT_SRC_BIT))
            throw vk::VulkanError(context.deviceName() + " cannot blit from R8G8B8A8_UNORM images");
        VkDevice device = context.device();
        VkSemaphoreCreateInfo semaphoreInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
        check(vkCreateSemaphore(device, &semaphoreInfo, nullptr, &imageAvailable_), "vkCreateSemaphore");
        VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        check(vkCreateFence(device, &fenceInfo, nullptr, &fence_), "vkCreateFence");
        VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        poolInfo.queueFamilyIndex = context.queueFamily();
        check(vkCreateCommandPool(device, &poolInfo, nullptr, &pool_), "vkCreateCommandPool");
        VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        alloc.commandPool = pool_;
        alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        alloc.commandBufferCount = 1;
        check(vkAllocateCommandBuffers(device, &alloc, &commands_), "vkAllocateCommandBuffers");
        createSwapchain();
    } catch (...) {
        release();
        throw;
    }
}

Presenter::~Presenter() { release(); }

void Presenter::release() {
    VkDevice device = context_.device();
    vkDeviceWaitIdle(device);
    destroySwapchain();
    context_.destroy(source_);
    context_.destroy(staging_);
    if (pool_) vkDestroyCommandPool(device, pool_, nullptr);
    if (fence_) vkDestroyFence(device, fence_, nullptr);
    if (imageAvailable_) vkDestroySemaphore(device, imageAvailable_, nullptr);
    if (surface_) vkDestroySurfaceKHR(context_.instance(), surface_, nullptr);
    pool_ = VK_NULL_HANDLE;
    fence_ = VK_NULL_HANDLE;
    imageAvailable_ = VK_NULL_HANDLE;
    surface_ = VK_NULL_HANDLE;
}

void Presenter::createSwapchain() {
    VkPhysicalDevice physical = context_.physicalDevice();
    VkSurfaceCapabilitiesKHR caps;
    check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface_, &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    int fbWidth = 0, fbHeight = 0;
    glfwGetFramebufferSize(window_, &fbWidth, &fbHeight);
    extent_ = caps.currentExtent;
    if (extent_.width == 0xffffffffu) {
        extent_.width = std::clamp(std::uint32_t(fbWidth), caps.minImageExtent.width, caps.maxImageExtent.width);
        extent_.height = std::clamp(std::uint32_t(fbHeight), caps.minImageExtent.height, caps.maxImageExtent.height);
    }
    if (extent_.width == 0 || extent_.height == 0) return;  // minimised: no swapchain until restored
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
        throw vk::VulkanError("the window's swapchain images cannot be written by transfers on " +
                              context_.deviceName());

    // An 8-bit UNORM format, no sRGB encoding: the window shows the bytes a
    // PNG of the image would hold.
    std::uint32_t count = 0;
    check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface_, &count, nullptr), "vkGetPhysicalDeviceSurfaceFormatsKHR");
    std::vector<VkSurfaceFormatKHR> formats(count);
    check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface_, &count, formats.data()),
          "vkGetPhysicalDeviceSurfaceFormatsKHR");
    VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (const VkSurfaceFormatKHR& f : formats)
        if ((f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) &&
            blitSupported(physical, f.format, VK_FORMAT_FEATURE_BLIT_DST_BIT)) {
            chosen = f;
            break;
        }
    if (chosen.format == VK_FORMAT_UNDEFINED)
        throw vk::VulkanError("the window offers no 8-bit UNORM swapchain format that " + context_.deviceName() +
                              " can blit to");
    format_ = chosen.format;

    VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    info.surface = surface_;
    info.minImageCount = caps.maxImageCount ? std::min(caps.minImageCount + 1, caps.maxImageCount) : caps.minImageCount + 1;
    info.imageFormat = chosen.format;
    info.imageColorSpace = chosen.colorSpace;
    info.imageExtent = extent_;
    info.imageArrayLayers = 1;
    info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                              ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                              : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always available; no tearing
    info.clipped = VK_TRUE;
    VkDevice device = context_.device();
    check(vkCreateSwapchainKHR(device, &info, nullptr, &swapchain_), "vkCreateSwapchainKHR");
    check(vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr), "vkGetSwapchainImagesKHR");
    images_.resize(count);
    check(vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data()), "vkGetSwapchainImagesKHR");
    renderFinished_.assign(count, VK_NULL_HANDLE);
    VkSemaphoreCreateInfo semaphoreInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    for (VkSemaphore& s : renderFinished_)
        check(vkCreateSemaphore(device, &semaphoreInfo, nullptr, &s), "vkCreateSemaphore");
}

void Presenter::destroySwapchain() {
    VkDevice device = context_.device();
    vkDeviceWaitIdle(device);
    for (VkSemaphore s : renderFinished_)
        if (s) vkDestroySemaphore(device, s, nullptr);
    renderFinished_.clear();
    images_.clear();
    if (swapchain_) vkDestroySwapchainKHR(device, swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
}

void Presenter::ensureSource(int width, int height) {
    if (source_.image && int(source_.width) == width && int(source_.height) == height) return;
    context_.destroy(source_);
    context_.destroy(staging_);
    source_ = context_.createImage(width, height, VK_FORMAT_R8G8B8A8_UNORM,
                                   VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    staging_ = context_.createBuffer(VkDeviceSize(width) * height * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::Context::Memory::HostCached);
}

// Into `cmd`: the staged frame copied into the source image, and blitted
// into `target` (cleared grey), scaled by a whole or fractional factor to
// fit, centred.
void Presenter::recordBlit(VkCommandBuffer cmd, VkImage target, int width, int height) {
    const double scale = std::min(double(extent_.width) / width, double(extent_.height) / height);
    const int w = std::max(1, int(width * scale)), h = std::max(1, int(height * scale));
    const int x0 = (int(extent_.width) - w) / 2, y0 = (int(extent_.height) - h) / 2;

    barrier(cmd, source_.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
            VK_ACCESS_TRANSFER_WRITE_BIT);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {std::uint32_t(width), std::uint32_t(height), 1};
    vkCmdCopyBufferToImage(cmd, staging_.buffer, source_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    barrier(cmd, source_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    barrier(cmd, target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
            VK_ACCESS_TRANSFER_WRITE_BIT);
    const VkClearColorValue grey{{0.12f, 0.12f, 0.12f, 1.0f}};
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &grey, 1, &range);
    barrier(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
            VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {width, height, 1};
    blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.dstOffsets[0] = {x0, y0, 0};
    blit.dstOffsets[1] = {x0 + w, y0 + h, 1};
    // Nearest: at 1:1 the window shows exactly the rendered bytes.
    vkCmdBlitImage(cmd, source_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
    barrier(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
            VK_ACCESS_TRANSFER_WRITE_BIT, 0);
}

bool Presenter::present(const std::vector<std::uint8_t>& rgba, int width, int height) {
    int fbWidth = 0, fbHeight = 0;
    glfwGetFramebufferSize(window_, &fbWidth, &fbHeight);
    if (fbWidth == 0 || fbHeight == 0) return false;  // minimised
    if (!swapchain_ || std::uint32_t(fbWidth) != extent_.width || std::uint32_t(fbHeight) != extent_.height) {
        destroySwapchain();
        createSwapchain();
        if (!swapchain_) return false;
    }
    ensureSource(width, height);
    std::memcpy(staging_.mapped, rgba.data(), std::size_t(width) * height * 4);

    VkDevice device = context_.device();
    std::uint32_t index = 0;
    VkResult r = vkAcquireNextImageKHR(device, swapchain_, UINT64_MAX, imageAvailable_, VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
        destroySwapchain();
        createSwapchain();
        return false;
    }
    if (r != VK_SUBOPTIMAL_KHR) check(r, "vkAcquireNextImageKHR");

    VkCommandBuffer cmd = commands_;
    check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    recordBlit(cmd, images_[index], width, height);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

    const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &imageAvailable_;
    submit.pWaitDstStageMask = &waitStage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &renderFinished_[index];
    check(context_.submit(submit, fence_), "vkQueueSubmit");

    VkPresentInfoKHR presentInfo{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    presentInfo.waitSemaphoreCount = 1;
    presentInfo.pWaitSemaphores = &renderFinished_[index];
    presentInfo.swapchainCount = 1;
    presentInfo.pSwapchains = &swapchain_;
    presentInfo.pImageIndices = &index;
    r = vkQueuePresentKHR(context_.queue(), &presentInfo);
    check(vkWaitForFences(device, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    check(vkResetFences(device, 1, &fence_), "vkResetFences");
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) {
        destroySwapchain();
        createSwapchain();
        return r == VK_SUBOPTIMAL_KHR;  // suboptimal still showed the image
    }
    check(r, "vkQueuePresentKHR");
    return true;
}

}  // namespace snell
