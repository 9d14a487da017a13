// `snell preview`: a GLFW window showing the compute renderer's image of a
// scene, live. The camera orbits, pans and zooms; keys switch what is traced;
// saving the scene file re-renders it; supersampled images refine frame by
// frame. A scripted mode renders N frames through the window and swapchain,
// saves a screenshot and returns (for tests).
#pragma once

#include <atomic>
#include <optional>
#include <stdexcept>
#include <string>

#include "gpu/GpuScene.h"
#include "vulkan/VulkanContext.h"

namespace snell {

// The preview's keys, as `H` prints them and `snell preview --help` lists them.
extern const char* const kPreviewKeys;

struct PreviewOptions {
    std::string scene;
    std::optional<int> size;         // the rendered image's side (default: the scene's view n)
    std::optional<int> depth;
    std::optional<double> minWeight;
    std::optional<int> supersample;
    int gpu = -1;
    bool validation = false;
    gpu::Precision precision = gpu::Precision::Fp32;
    gpu::Traversal traversal = gpu::Traversal::Auto;
    vk::RayQueries rayQueries = vk::RayQueries::OnGpus;  // what the traversal needs enabled
    bool quiet = false;
    // Scripted mode: after `frames` frames (> 0), save `screenshot` (when set)
    // and return. `orbitDegrees` orbits the camera before the first frame;
    // `orbitPerFrame` before every frame, as a drag would (the moving camera).
    int frames = 0;
    std::string screenshot;
    double orbitDegrees = 0.0;
    double orbitPerFrame = 0.0;
    const std::atomic<bool>* cancel = nullptr;  // set to close the window
    std::string pipelineCachePath;              // vk::ContextOptions::pipelineCachePath
};

// No window could be opened (no display, no GLFW Vulkan support, ...).
class WindowError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Runs until the window is closed (or the script ends). Throws ParseError
// for the scene as first read (later errors are shown, not thrown),
// WindowError, vk::VulkanError and ImageIOError.
void runPreview(const PreviewOptions& options);

}  // namespace snell
