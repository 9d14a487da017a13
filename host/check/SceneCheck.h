// `snell check`: what a scene holds and what looks wrong in it, without
// rendering. No Vulkan.
#pragma once

#include <string>
#include <vector>

#include "render/RenderRequest.h"
#include "scene/Scene.h"

namespace snell {

struct SceneReport {
    std::size_t spheres = 0, trueSpheres = 0, ellipsoids = 0, lights = 0;
    std::size_t materials = 0, reflective = 0, refractive = 0;  // spheres with ks > 0 / kt > 0
    bool amplifying = false;
    dvec3 lower{0.0}, upper{0.0};  // bounding box of all spheres (zero when there are none)
    std::vector<Diagnostic> warnings;  // sceneWarnings at the scene's own size
    std::string json(const Scene& scene) const;
    std::string text(const Scene& scene) const;
};

// What a render of the scene will be: its image size, the pixels it renders
// of it (--region; empty: all of them), supersampling and trace settings.
struct RenderShape {
    int size = 0;
    int supersample = 1;
    bool defaultTree = true;  // the default trace settings (no --depth, --min-weight, --tolerance)
    TraceSettings trace = kDefaultSettings;
    PixelWindow window;
    PixelWindow area() const { return window.empty() ? PixelWindow{0, 0, size, size} : window; }
};

// What looks wrong in a scene, the same for `check` and `render` (one set of
// warnings, one set of thresholds), each saying what to do: the parser's;
// lights inside spheres; spheres behind the camera; a scene that can only
// render the background or black; a render expected to trace many rays
// (its size, or its amplifying materials at the defaults; rays counted on a
// few pixels with the CPU reference). `path`: the scene's file, for the warnings' locations.
std::vector<Diagnostic> sceneWarnings(const Scene& scene, const std::string& path, RenderShape shape);

// The report of `snell check`: warnings at the scene's own size.
SceneReport checkScene(const Scene& scene, const std::string& path);

}  // namespace snell
