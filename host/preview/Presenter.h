// The preview's window side: a Vulkan surface and swapchain for a GLFW window,
// and present(), which shows an 8-bit RGBA image (the renderer's output,
// converted exactly as PNG output is) scaled to fit the window, letterboxed,
// by a blit. Swapchains that go out of date (resize) are rebuilt.
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "vulkan/VulkanContext.h"

struct GLFWwindow;

namespace snell {

class Presenter {
public:
    // Throws vk::VulkanError when the device cannot present to the window.
    Presenter(vk::Context& context, GLFWwindow* window);
    ~Presenter();
    Presenter(const Presenter&) = delete;
    Presenter& operator=(const Presenter&) = delete;

    // Shows `rgba` (width × height, 4 bytes a pixel); returns false when
    // nothing could be shown (the window is minimised, or its swapchain was
    // out of date and has been rebuilt: call again).
    bool present(const std::vector<std::uint8_t>& rgba, int width, int height);

private:
    void release();
    void createSwapchain();
    void destroySwapchain();
    void ensureSource(int width, int height);
    void recordBlit(VkCommandBuffer cmd, VkImage target, int width, int height);

    vk::Context& context_;
    GLFWwindow* window_;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkExtent2D extent_{0, 0};
    std::vector<VkImage> images_;
    std::vector<VkSemaphore> renderFinished_;  // one per swapchain image
    VkSemaphore imageAvailable_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer commands_ = VK_NULL_HANDLE;
    // The image to show, staged in host memory and copied to a device image.
    vk::Buffer staging_;
    vk::DeviceImage source_;
};

}  // namespace snell
