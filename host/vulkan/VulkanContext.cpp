#include "vulkan/VulkanContext.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <type_traits>

#include <unistd.h>

namespace snell::vk {

namespace {

constexpr const char* kInstallHint =
    "install a Vulkan driver: on Debian/Ubuntu 'apt-get install mesa-vulkan-drivers' gives the "
    "lavapipe CPU device (or install your GPU's Vulkan driver)";

const char* typeName(VkPhysicalDeviceType t) {
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
    }
}

int typeRank(VkPhysicalDeviceType t) {
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
    }
}

std::string versionString(std::uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}

bool hasLayer(const char* name) {
    std::uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

// Check a physical device for what snell needs; fills `family` and a report.
// The device extensions of the ray-query traversal.
constexpr const char* kRayQueryExtensions[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                               VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                               VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};

bool hasExtension(const std::vector<VkExtensionProperties>& available, const std::string& name) {
    return std::any_of(available.begin(), available.end(),
                       [&](const VkExtensionProperties& p) { return name == p.extensionName; });
}

// Whether the device can trace through ray queries (its extensions and the
// features they need); if not, why not.
bool supportsRayQueries(VkPhysicalDevice device, std::string& why) {
    std::uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> available(count);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, available.data());
    for (const char* e : kRayQueryExtensions)
        if (!hasExtension(available, e)) {
            why = std::string("the device lacks ") + e;
            return false;
        }
    VkPhysicalDeviceRayQueryFeaturesKHR rayQuery{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accel{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &rayQuery};
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &accel};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &v12};
    vkGetPhysicalDeviceFeatures2(device, &features);
    if (!rayQuery.rayQuery || !accel.accelerationStructure || !v12.bufferDeviceAddress) {
        why = "the device lacks the rayQuery, accelerationStructure or bufferDeviceAddress feature";
        return false;
    }
    return true;
}

// Whether the device has shader objects (the extension and its feature).
bool supportsShaderObjects(VkPhysicalDevice device, const std::vector<VkExtensionProperties>& available) {
    if (!hasExtension(available, VK_EXT_SHADER_OBJECT_EXTENSION_NAME)) return false;
    VkPhysicalDeviceShaderObjectFeaturesEXT objects{kStructureTypePhysicalDeviceShaderObjectFeatures};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &objects};
    vkGetPhysicalDeviceFeatures2(device, &features);
    return objects.shaderObject;
}

DeviceReport examine(VkPhysicalDevice device, int index, std::uint32_t& family,
                     const std::vector<std::string>& extensions) {
    DeviceReport report;
    report.index = index;
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(device, &props);
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
    if (props.apiVersion >= VK_API_VERSION_1_2) vkGetPhysicalDeviceProperties2(device, &props2);
    report.name = props.deviceName;
    report.type = typeName(props.deviceType);
    report.driver = std::string(driver.driverName) + (driver.driverInfo[0] ? std::string(" ") + driver.driverInfo : "");
    if (props.apiVersion < VK_API_VERSION_1_2) {
        report.reason = "supports Vulkan " + versionString(props.apiVersion) + ", snell needs 1.2";
        return report;
    }
    std::uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
    bool found = false;
    for (std::uint32_t i = 0; i < count && !found; ++i) {
        if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) { family = i; found = true; }
    }
    if (!found) {
        report.reason = "has no compute queue";
        return report;
    }
    std::uint32_t extCount = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &extCount, nullptr);
    std::vector<VkExtensionProperties> available(extCount);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &extCount, available.data());
    for (const std::string& e : extensions) {
        if (!hasExtension(available, e)) {
            report.reason = "lacks the device extension " + e;
            return report;
        }
    }
    VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 withSubgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &subgroup};
    vkGetPhysicalDeviceProperties2(device, &withSubgroup);
    const VkSubgroupFeatureFlags needed =
        VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_VOTE_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
    if (!(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) || (subgroup.supportedOperations & needed) != needed) {
        report.reason = "lacks basic, vote and arithmetic subgroup operations in compute shaders";
        return report;
    }
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &v12};
    vkGetPhysicalDeviceFeatures2(device, &features);
    if (!v12.bufferDeviceAddress) {
        // The kernel reads the BVH's nodes through their address on some
        // drivers, and so declares the capability on all.
        report.reason = "lacks the bufferDeviceAddress feature (Vulkan 1.2, required from 1.3)";
        return report;
    }
    if (!features.features.shaderInt64) {
        // The kernel moves 16-byte words through addresses as 64-bit halves.
        report.reason = "lacks the shaderInt64 feature";
        return report;
    }
    report.usable = true;
    std::string ignored;
    report.rayQueries = supportsRayQueries(device, ignored);
    report.shaderObjects = supportsShaderObjects(device, available);
    report.fp64Refusal = Context::fp64RefusalFor(driver.driverID);
    return report;
}

VkInstance createInstance(const std::vector<std::string>& extensions, bool validation, bool& debugUtils) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "snell";
    app.applicationVersion = VK_MAKE_API_VERSION(0, 1, 0, 0);
    app.pEngineName = "snell";
    app.apiVersion = VK_API_VERSION_1_2;
    std::vector<const char*> exts;
    for (const std::string& e : extensions) exts.push_back(e.c_str());
    std::vector<const char*> layers;
    debugUtils = false;
    if (validation) {
        if (!hasLayer("VK_LAYER_KHRONOS_validation"))
            throw VulkanError("validation was requested but VK_LAYER_KHRONOS_validation is not installed "
                              "(apt-get install vulkan-validationlayers)");
        layers.push_back("VK_LAYER_KHRONOS_validation");
        exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        debugUtils = true;
    }
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledExtensionCount = static_cast<std::uint32_t>(exts.size());
    info.ppEnabledExtensionNames = exts.data();
    info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();
    VkInstance instance = VK_NULL_HANDLE;
    const VkResult r = vkCreateInstance(&info, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
        throw NoDeviceError(std::string("no Vulkan driver found (vkCreateInstance: ") + resultName(r) + "): " + kInstallHint, r);
    check(r, "vkCreateInstance");
    return instance;
}

std::vector<VkPhysicalDevice> enumerate(VkInstance instance) {
    std::uint32_t count = 0;
    check(vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices");
    std::vector<VkPhysicalDevice> devices(count);
    check(vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices");
    devices.resize(count);
    return devices;
}

}  // namespace

const char* resultName(VkResult result) {
    switch (result) {
#define SNELL_CASE(x) case x: return #x;
    SNELL_CASE(VK_SUCCESS) SNELL_CASE(VK_NOT_READY) SNELL_CASE(VK_TIMEOUT) SNELL_CASE(VK_INCOMPLETE)
    SNELL_CASE(VK_ERROR_OUT_OF_HOST_MEMORY) SNELL_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SNELL_CASE(VK_ERROR_INITIALIZATION_FAILED) SNELL_CASE(VK_ERROR_DEVICE_LOST)
    SNELL_CASE(VK_ERROR_MEMORY_MAP_FAILED) SNELL_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SNELL_CASE(VK_ERROR_EXTENSION_NOT_PRESENT) SNELL_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SNELL_CASE(VK_ERROR_INCOMPATIBLE_DRIVER) SNELL_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SNELL_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED) SNELL_CASE(VK_ERROR_FRAGMENTED_POOL)
    SNELL_CASE(VK_ERROR_OUT_OF_POOL_MEMORY) SNELL_CASE(VK_ERROR_SURFACE_LOST_KHR)
    SNELL_CASE(VK_ERROR_OUT_OF_DATE_KHR) SNELL_CASE(VK_SUBOPTIMAL_KHR)
    SNELL_CASE(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR) SNELL_CASE(VK_ERROR_UNKNOWN)
#undef SNELL_CASE
    default: return "VkResult(unknown)";
    }
}

void check(VkResult result, const char* call) {
    if (result >= 0) return;
    std::string message = std::string(call) + " failed with " + resultName(result);
    switch (result) {
    case VK_ERROR_DEVICE_LOST:
        message += ": the Vulkan device was lost (driver crash, GPU reset or a render that ran too long); "
                   "no image was written. Try a smaller --size, or update the driver";
        break;
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
        message += ": the device ran out of memory; no image was written. Try a smaller --size or a scene with fewer "
                   "spheres";
        break;
    case VK_ERROR_OUT_OF_HOST_MEMORY:
        message += ": the host ran out of memory";
        break;
    default: break;
    }
    throw VulkanError(message, result);
}

void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess,
                  VkAccessFlags dstAccess, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

FaultInjection parseFaultInjection(const std::string& text) {
    FaultInjection f;
    const std::size_t colon = text.find(':');
    const std::string kind = text.substr(0, colon);
    if (kind == "device-lost") f.kind = FaultInjection::Kind::DeviceLost;
    else if (kind == "out-of-device-memory") f.kind = FaultInjection::Kind::OutOfDeviceMemory;
    else throw std::invalid_argument("unknown fault '" + kind + "' (device-lost or out-of-device-memory)");
    if (colon != std::string::npos) {
        const std::string n = text.substr(colon + 1);
        if (n.empty() || n.size() > 9 || n.find_first_not_of("0123456789") != std::string::npos || std::stoul(n) == 0)
            throw std::invalid_argument("fault count '" + n + "' is not a positive integer");
        f.at = static_cast<std::uint32_t>(std::stoul(n));
    }
    return f;
}

VkResult Context::submit(const VkSubmitInfo& info, VkFence fence) {
    if (fault_.kind == FaultInjection::Kind::DeviceLost && ++submissions_ == fault_.at) return VK_ERROR_DEVICE_LOST;
    return vkQueueSubmit(queue_, 1, &info, fence);
}

std::vector<DeviceReport> Context::listDevices() {
    bool debugUtils = false;
    VkInstance instance = createInstance({}, false, debugUtils);
    std::vector<DeviceReport> reports;
    try {
        int index = 0;
        for (VkPhysicalDevice d : enumerate(instance)) {
            std::uint32_t family = 0;
            reports.push_back(examine(d, index++, family, {}));
        }
    } catch (...) {
        vkDestroyInstance(instance, nullptr);
        throw;
    }
    vkDestroyInstance(instance, nullptr);
    return reports;
}

Context::Context(const ContextOptions& options) : fault_(options.fault) {
    bool debugUtils = false;
    instance_ = createInstance(options.instanceExtensions, options.validation, debugUtils);
    try {
        if (debugUtils) {
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
            VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
            info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
            info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
            info.pfnUserCallback = debugCallback;
            info.pUserData = this;
            if (create) check(create(instance_, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
        }
        const std::vector<VkPhysicalDevice> devices = enumerate(instance_);
        std::uint32_t family = 0;
        const int best = chooseDevice(devices, options, family);
        physical_ = devices[best];
        queueFamily_ = family;
        deviceName_ = reports_[best].name;
        driverInfo_ = reports_[best].driver;
        vkGetPhysicalDeviceProperties(physical_, &properties_);
        VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
        VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES, &subgroup};
        VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
        vkGetPhysicalDeviceProperties2(physical_, &props2);
        driverId_ = driver.driverID;
        subgroupSize_ = subgroup.subgroupSize;
        vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
        std::uint32_t count = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &count, nullptr);
        std::vector<VkQueueFamilyProperties> qf(count);
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &count, qf.data());
        timestampValidBits_ = qf[queueFamily_].timestampValidBits;

        createDevice(options.deviceExtensions, options.rayQueries, options.shaderObjects && !options.validation);
        if (!shaderObjects_.enabled && shaderObjects_.absence.empty())
            shaderObjects_.absence = options.shaderObjects
                                         ? "validation is on, and Debian 12's validation layer cannot check shader objects"
                                         : "shader objects were not asked for";
        openPipelineCache(options.pipelineCachePath);
    } catch (...) {
        release();
        throw;
    }
}

// Examines every device (reports_: why each was passed over) and picks the
// one asked for (--gpu), else the usable one of the most preferred type;
// `family` is its compute queue family.
int Context::chooseDevice(const std::vector<VkPhysicalDevice>& devices, const ContextOptions& options,
                          std::uint32_t& family) {
    if (devices.empty()) throw NoDeviceError(std::string("no Vulkan device found: ") + kInstallHint);
    int best = -1, bestRank = -1;
    std::vector<std::uint32_t> families(devices.size());
    for (std::size_t i = 0; i < devices.size(); ++i) {
        reports_.push_back(examine(devices[i], static_cast<int>(i), families[i], options.deviceExtensions));
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(devices[i], &props);
        if (options.deviceIndex >= 0) {
            if (static_cast<int>(i) != options.deviceIndex && reports_.back().usable)
                reports_.back().reason = "not the device asked for (--gpu " + std::to_string(options.deviceIndex) + ")";
            continue;
        }
        if (reports_.back().usable && typeRank(props.deviceType) > bestRank) {
            best = static_cast<int>(i);
            bestRank = typeRank(props.deviceType);
        }
    }
    if (options.deviceIndex >= 0) {
        if (options.deviceIndex >= static_cast<int>(devices.size()))
            throw NoDeviceError("--gpu " + std::to_string(options.deviceIndex) + ": there are only " +
                                std::to_string(devices.size()) + " Vulkan device(s); see 'snell devices'");
        if (!reports_[options.deviceIndex].usable)
            throw NoDeviceError("device " + std::to_string(options.deviceIndex) + " (" +
                                reports_[options.deviceIndex].name + ") cannot be used: " +
                                reports_[options.deviceIndex].reason);
        best = options.deviceIndex;
    }
    if (best < 0) {
        std::string why = "no usable Vulkan device:";
        for (const DeviceReport& r : reports_) why += "\n  device " + std::to_string(r.index) + " " + r.name + ": " + r.reason;
        throw NoDeviceError(why + "\n" + kInstallHint);
    }
    for (DeviceReport& r : reports_)
        if (r.index != best && r.usable && r.reason.empty()) r.reason = "a device of a preferred type was chosen";
    family = families[best];
    return best;
}

// The logical device with one compute queue, shader doubles where the device
// has them, ray queries where asked for and the device has them, and the
// one-off command pool and fence.
void Context::createDevice(const std::vector<std::string>& extensions, RayQueries rayQueries, bool shaderObjects) {
    VkPhysicalDeviceFeatures supported;
    vkGetPhysicalDeviceFeatures(physical_, &supported);
    VkPhysicalDeviceFeatures2 enabled{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    float64_ = supported.shaderFloat64;
    enabled.features.shaderFloat64 = supported.shaderFloat64;
    enabled.features.shaderInt64 = VK_TRUE;  // every device snell uses has it (examine)
    VkPhysicalDeviceRayQueryFeaturesKHR rayQuery{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accel{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &rayQuery};
    // Every device snell uses has buffer device addresses (examine).
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    v12.bufferDeviceAddress = VK_TRUE;
    enabled.pNext = &v12;
    if (rayQueries == RayQueries::Off) {
        rayQueryAbsence_ = "ray queries were not asked for";
    } else if (rayQueries == RayQueries::OnGpus && isCpuDevice()) {
        rayQueryAbsence_ = "not enabled on a CPU device, where snell's BVH walk is faster";
    } else if (supportsRayQueries(physical_, rayQueryAbsence_)) {
        rayQueries_ = true;
        rayQuery.rayQuery = VK_TRUE;
        accel.accelerationStructure = VK_TRUE;
        v12.pNext = &accel;
    }
    std::uint32_t extCount = 0;
    vkEnumerateDeviceExtensionProperties(physical_, nullptr, &extCount, nullptr);
    std::vector<VkExtensionProperties> available(extCount);
    vkEnumerateDeviceExtensionProperties(physical_, nullptr, &extCount, available.data());
    VkPhysicalDeviceShaderObjectFeaturesEXT objects{kStructureTypePhysicalDeviceShaderObjectFeatures};
    if (!supportsShaderObjects(physical_, available)) {
        shaderObjects_.absence = "the device lacks " VK_EXT_SHADER_OBJECT_EXTENSION_NAME;
    } else if (shaderObjects) {
        shaderObjects_.enabled = true;
        objects.shaderObject = VK_TRUE;
        objects.pNext = enabled.pNext;
        enabled.pNext = &objects;
        VkPhysicalDeviceShaderObjectPropertiesEXT properties{kStructureTypePhysicalDeviceShaderObjectProperties};
        VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &properties};
        vkGetPhysicalDeviceProperties2(physical_, &props2);
        std::copy(std::begin(properties.shaderBinaryUUID), std::end(properties.shaderBinaryUUID),
                  shaderObjects_.binaryUuid.begin());
        shaderObjects_.binaryVersion = properties.shaderBinaryVersion;
    }
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = queueFamily_;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    std::vector<const char*> exts;
    for (const std::string& e : extensions) exts.push_back(e.c_str());
    if (rayQueries_)
        for (const char* e : kRayQueryExtensions) exts.push_back(e);
    if (shaderObjects_.enabled) exts.push_back(VK_EXT_SHADER_OBJECT_EXTENSION_NAME);
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &enabled};
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queueInfo;
    info.enabledExtensionCount = static_cast<std::uint32_t>(exts.size());
    info.ppEnabledExtensionNames = exts.data();
    check(vkCreateDevice(physical_, &info, nullptr, &device_), "vkCreateDevice");
    vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
    if (shaderObjects_.enabled) {
        auto load = [&](auto& function, const char* name) {
            function = reinterpret_cast<std::remove_reference_t<decltype(function)>>(vkGetDeviceProcAddr(device_, name));
            if (!function) throw VulkanError(std::string("the driver lists VK_EXT_shader_object but lacks ") + name);
        };
        load(shaderObjects_.create, "vkCreateShadersEXT");
        load(shaderObjects_.destroy, "vkDestroyShaderEXT");
        load(shaderObjects_.binaryData, "vkGetShaderBinaryDataEXT");
        load(shaderObjects_.bind, "vkCmdBindShadersEXT");
    }
    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = queueFamily_;
    check(vkCreateCommandPool(device_, &poolInfo, nullptr, &pool_), "vkCreateCommandPool");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(device_, &fenceInfo, nullptr, &fence_), "vkCreateFence");
}

// The pipeline cache: what earlier runs compiled, when the file holds data
// for this device and driver (the driver checks and ignores any other).
void Context::openPipelineCache(const std::string& path) {
    pipelineCachePath_ = path;
    std::vector<char> initial;
    if (!pipelineCachePath_.empty()) {
        std::ifstream in(pipelineCachePath_, std::ios::binary);
        initial.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    VkPipelineCacheCreateInfo cacheInfo{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    cacheInfo.initialDataSize = initial.size();
    cacheInfo.pInitialData = initial.empty() ? nullptr : initial.data();
    if (vkCreatePipelineCache(device_, &cacheInfo, nullptr, &pipelineCache_) != VK_SUCCESS) {
        cacheInfo.initialDataSize = 0;  // unreadable data: start empty
        cacheInfo.pInitialData = nullptr;
        check(vkCreatePipelineCache(device_, &cacheInfo, nullptr, &pipelineCache_), "vkCreatePipelineCache");
    }
}

Context::~Context() { release(); }

int Context::mesaMajor() const {
    const std::size_t at = driverInfo_.find("Mesa ");
    if (at == std::string::npos) return 0;
    return std::atoi(driverInfo_.c_str() + at + 5);
}

std::string Context::cacheDirectory() const {
    return pipelineCachePath_.empty() ? std::string() : std::filesystem::path(pipelineCachePath_).parent_path().string();
}

void Context::savePipelineCache() {
    // Best effort: a cache that cannot be written only makes the next start slower.
    std::size_t size = 0;
    if (vkGetPipelineCacheData(device_, pipelineCache_, &size, nullptr) != VK_SUCCESS || size == 0) return;
    std::vector<char> data(size);
    if (vkGetPipelineCacheData(device_, pipelineCache_, &size, data.data()) != VK_SUCCESS) return;
    std::error_code ignored;
    const std::filesystem::path path(pipelineCachePath_);
    std::filesystem::create_directories(path.parent_path(), ignored);
    const std::string temporary = pipelineCachePath_ + ".tmp-" + std::to_string(::getpid());
    {
        std::ofstream out(temporary, std::ios::binary);
        out.write(data.data(), std::streamsize(size));
        if (!out) {
            std::filesystem::remove(temporary, ignored);
            return;
        }
    }
    std::filesystem::rename(temporary, path, ignored);  // atomic: concurrent runs never see half a file
    if (ignored) std::filesystem::remove(temporary, ignored);
}

void Context::release() {
    if (device_) {
        vkDeviceWaitIdle(device_);
        if (pipelineCache_) {
            if (!pipelineCachePath_.empty()) savePipelineCache();
            vkDestroyPipelineCache(device_, pipelineCache_, nullptr);
            pipelineCache_ = VK_NULL_HANDLE;
        }
        if (fence_) vkDestroyFence(device_, fence_, nullptr);
        if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
        vkDestroyDevice(device_, nullptr);
        device_ = VK_NULL_HANDLE;
        fence_ = VK_NULL_HANDLE;
        pool_ = VK_NULL_HANDLE;
    }
    if (messenger_) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance_, messenger_, nullptr);
        messenger_ = VK_NULL_HANDLE;
    }
    if (instance_) {
        vkDestroyInstance(instance_, nullptr);
        instance_ = VK_NULL_HANDLE;
    }
}

VKAPI_ATTR VkBool32 VKAPI_CALL Context::debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                      VkDebugUtilsMessageTypeFlagsEXT,
                                                      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<Context*>(user);
    ++self->validationMessages_;
    std::fprintf(stderr, "snell: validation %s: %s\n",
                 severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
                 data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

std::string Context::fp64RefusalFor(VkDriverId driver) {
    // On an H200 with NVIDIA's driver 580.159 every fp64 agreement test
    // failed (up to every pixel wrong), each differently as the shader's
    // shape changed, while the fp64 intersection fuzz test passed there: the
    // fp64 kernel is not to be trusted on it (docs/accuracy.md).
    if (driver == VK_DRIVER_ID_NVIDIA_PROPRIETARY)
        return "the fp64 shader renders wrong images on NVIDIA's driver (every fp64 agreement test failed on it)";
    return "";
}

}  // namespace snell::vk
