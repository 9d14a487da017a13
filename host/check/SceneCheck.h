// `snell check`: what a scene holds and what looks wrong in it, without
// rendering. No Vulkan.
#pragma once

#include <string>
#include <vector>

#include "render/RenderRequest.h"
#include "scene/Parser.h"
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
// warnings, one set of thresholds), each saying what to do, in line order
// (those about the whole file last): the parser's; lights inside spheres;
// spheres behind the camera; amplifying materials; a scene that can only
// render the background or black; a render expected to trace many rays
// (its size, or its amplifying materials at the defaults; rays counted on a
// few pixels with the CPU reference). `path`: the scene's file, for the warnings' locations.
std::vector<Diagnostic> sceneWarnings(const Scene& scene, const std::string& path, RenderShape shape);

// The warnings of a scene with errors (ParseOutcome): those about the lines
// that parsed, in line order; none about the scene as a whole, which it is not.
std::vector<Diagnostic> partialSceneWarnings(const Scene& scene, const std::string& path);

// The scene of a parse without errors; else throws its ParseError, reported
// with the partial scene's warnings where `withWarnings`.
Scene sceneOrErrors(ParseOutcome outcome, const std::string& path, bool withWarnings);

// The report of `snell check`: warnings at the scene's own size.
SceneReport checkScene(const Scene& scene, const std::string& path);

// Diagnostics as a JSON array of {"file", "line", "column", "message"}; line
// and column are null for those about the whole file.
std::string diagnosticsJson(const std::vector<Diagnostic>& diagnostics);
// `snell check --json` of a scene with errors: its name, errors (the listed
// ones, and how many more), and the warnings of the errors' report.
std::string errorsJson(const std::string& sceneName, const ParseError& errors);

}  // namespace snell
