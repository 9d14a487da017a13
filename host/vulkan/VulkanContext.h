// A small, honest Vulkan setup: instance, one physical device chosen with the
// reasons each other one was passed over, one compute queue, and buffer/image
// helpers. Every VkResult goes through check(), which throws VulkanError with
// a message a user can act on.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "vulkan/ShaderObject.h"

namespace snell::vk {

class VulkanError : public std::runtime_error {
public:
    VulkanError(const std::string& message, VkResult result = VK_SUCCESS)
        : std::runtime_error(message), result_(result) {}
    VkResult result() const { return result_; }

private:
    VkResult result_;
};

// No usable Vulkan device (or no Vulkan at all): tells what to install.
class NoDeviceError : public VulkanError {
public:
    using VulkanError::VulkanError;
};

const char* resultName(VkResult result);
void check(VkResult result, const char* call);
#define SNELL_VK_CHECK(call) ::snell::vk::check((call), #call)

// A testing hook: the driver's Nth queue submission fails with
// VK_ERROR_DEVICE_LOST, or its Nth memory allocation with
// VK_ERROR_OUT_OF_DEVICE_MEMORY, as a failing GPU would report them, so the
// error paths are tested without one (snell reads $SNELL_INJECT_FAULT).
struct FaultInjection {
    enum class Kind { None, DeviceLost, OutOfDeviceMemory };
    Kind kind = Kind::None;
    std::uint32_t at = 1;  // the Nth submission or allocation, from 1
};

// A layout transition of a whole single-level colour image.
void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess,
                  VkAccessFlags dstAccess, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage);

// "device-lost[:N]" or "out-of-device-memory[:N]"; throws std::invalid_argument.
FaultInjection parseFaultInjection(const std::string& text);

// Whether the device's own ray traversal (VK_KHR_ray_query over
// VK_KHR_acceleration_structure, with buffer device addresses) is enabled
// where the device has it: never, on GPUs only (the default: on lavapipe,
// snell's BVH walk measured faster; docs/performance.md, "Drivers and
// devices"), or on any device.
enum class RayQueries { Off, OnGpus, On };

struct ContextOptions {
    int deviceIndex = -1;         // -1: choose (discrete GPU first); else this index
    bool validation = false;      // enable VK_LAYER_KHRONOS_validation
    std::vector<std::string> instanceExtensions;  // e.g. what GLFW needs
    std::vector<std::string> deviceExtensions;
    FaultInjection fault;
    // Where compiled pipelines are kept between runs (read at start, written
    // back at the end); empty: no cache on disk.
    std::string pipelineCachePath;
    RayQueries rayQueries = RayQueries::OnGpus;
    // Kernels as shader objects whose binaries are kept, where the device has
    // them (vulkan/ShaderObject.h); never under validation, whose layer in
    // Debian 12 cannot check them.
    bool shaderObjects = true;
};

struct DeviceReport {
    int index = 0;
    std::string name;
    std::string type;
    std::string driver;
    bool usable = false;
    std::string reason;  // why it was passed over, when it was
    bool rayQueries = false;  // has ray queries and acceleration structures
    bool shaderObjects = false;  // has VK_EXT_shader_object: kernels start from kept binaries
    std::string fp64Refusal;  // why --precision fp64 is refused here, if it is (Context::fp64Refusal)
};

struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void* mapped = nullptr;  // host-visible buffers stay mapped
};

// A device-local 2D image (the preview's frame, copied and blitted).
struct DeviceImage {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    std::uint32_t width = 0, height = 0;
};

class Context {
public:
    // Throws NoDeviceError when no device fits, VulkanError on other failures.
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physicalDevice() const { return physical_; }
    VkDevice device() const { return device_; }
    VkQueue queue() const { return queue_; }
    std::uint32_t queueFamily() const { return queueFamily_; }
    const VkPhysicalDeviceProperties& properties() const { return properties_; }
    const std::string& deviceName() const { return deviceName_; }
    const std::string& driverInfo() const { return driverInfo_; }
    bool timestampsSupported() const { return timestampValidBits_ > 0 && properties_.limits.timestampComputeAndGraphics; }
    bool float64Supported() const { return float64_; }
    // Why --precision fp64 is refused on this device although it has shader
    // doubles (a driver it was measured to render wrong on); empty: it is not.
    std::string fp64Refusal() const { return fp64RefusalFor(driverId_); }
    static std::string fp64RefusalFor(VkDriverId driver);
    // The device's ray traversal is enabled (ContextOptions::rayQueries); if
    // not, rayQueryAbsence() says why, for a message.
    bool rayQueriesEnabled() const { return rayQueries_; }
    const std::string& rayQueryAbsence() const { return rayQueryAbsence_; }
    // Shader objects (ContextOptions::shaderObjects): enabled, or why not.
    const ShaderObjects& shaderObjects() const { return shaderObjects_; }
    bool isCpuDevice() const { return properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
    // The lanes of a subgroup (a SIMD row) in compute shaders.
    std::uint32_t subgroupSize() const { return subgroupSize_; }
    // The size of the largest device-local memory heap.
    VkDeviceSize deviceLocalBytes() const;
    // Mesa's llvmpipe (lavapipe): its shaders end all loops after 65535
    // iterations per SIMD row and dispatch, which the renderer works around.
    bool isLlvmpipe() const { return driverId_ == VK_DRIVER_ID_MESA_LLVMPIPE; }
    // The major version of a Mesa driver (from its driver info, "Mesa 25.0.7"); 0 for others.
    int mesaMajor() const;
    // Validation-layer errors and warnings reported so far.
    std::uint32_t validationMessages() const { return validationMessages_; }

    // Where a buffer lives. A usage with VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT
    // gets memory that has one (deviceAddress).
    enum class Memory {
        Device,       // device-local where possible; the host never maps it
        HostCached,   // mapped, host-cached where possible: the host reads much of what the device wrote
        DeviceMapped, // mapped, device-local where possible: the device works on it (atomics, frequent
                      // writes) while the host peeks at a few words; on a discrete GPU host memory
                      // would send every one of those over the bus
    };
    Buffer createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, Memory memory);
    // A device-local buffer holding `bytes` (staged through a host buffer when
    // device-local memory is not host-visible).
    Buffer createBufferWithData(const void* bytes, VkDeviceSize size, VkBufferUsageFlags usage);
    void destroy(Buffer& buffer);
    VkDeviceAddress deviceAddress(const Buffer& buffer) const;
    // A device-local 2D image, for transfers (no view).
    DeviceImage createImage(std::uint32_t width, std::uint32_t height, VkFormat format, VkImageUsageFlags usage);
    void destroy(DeviceImage& image);

    // The pipeline cache (VK_NULL_HANDLE when none could be made).
    VkPipelineCache pipelineCache() const { return pipelineCache_; }
    // Where the run keeps what it compiles (the pipeline cache's directory);
    // empty: nothing is kept.
    std::string cacheDirectory() const;

    // vkQueueSubmit on the context's queue (through the fault-injection hook).
    VkResult submit(const VkSubmitInfo& info, VkFence fence);

    // Record and run a one-off command buffer, waiting for it to finish.
    template <typename Record>
    void submitAndWait(Record record) {
        VkCommandBuffer cmd = beginOneOff();
        record(cmd);
        endOneOffAndWait(cmd);
    }

    // Every available device with why it would or would not be used.
    static std::vector<DeviceReport> listDevices();

private:
    int chooseDevice(const std::vector<VkPhysicalDevice>& devices, const ContextOptions& options,
                     std::uint32_t& family);
    void createDevice(const std::vector<std::string>& extensions, RayQueries rayQueries, bool shaderObjects);
    void openPipelineCache(const std::string& path);
    std::uint32_t findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                 VkMemoryPropertyFlags preferred) const;
    void release();
    VkResult allocate(const VkMemoryAllocateInfo& info, VkDeviceMemory* memory);
    VkCommandBuffer beginOneOff();
    void endOneOffAndWait(VkCommandBuffer cmd);
    static VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                        VkDebugUtilsMessageTypeFlagsEXT types,
                                                        const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                        void* user);

    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    std::uint32_t queueFamily_ = 0;
    std::uint32_t timestampValidBits_ = 0;
    std::uint32_t subgroupSize_ = 0;
    bool float64_ = false;
    bool rayQueries_ = false;
    std::string rayQueryAbsence_;
    ShaderObjects shaderObjects_;
    VkDriverId driverId_{};
    VkPhysicalDeviceProperties properties_{};
    VkPhysicalDeviceMemoryProperties memory_{};
    std::string deviceName_;
    std::string driverInfo_;
    std::vector<DeviceReport> reports_;
    std::uint32_t validationMessages_ = 0;
    FaultInjection fault_;
    VkPipelineCache pipelineCache_ = VK_NULL_HANDLE;
    std::string pipelineCachePath_;
    void savePipelineCache();
    std::uint32_t submissions_ = 0, allocations_ = 0;
};

}  // namespace snell::vk
