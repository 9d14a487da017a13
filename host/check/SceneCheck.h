// `snell check`: what a scene holds and what looks wrong in it, without
// rendering. No Vulkan.
#pragma once

#include <string>
#include <vector>

#include "scene/Scene.h"

namespace snell {

struct SceneReport {
    std::size_t spheres = 0, trueSpheres = 0, ellipsoids = 0, lights = 0;
    std::size_t materials = 0, reflective = 0, refractive = 0;  // spheres with ks > 0 / kt > 0
    bool amplifying = false;
    dvec3 lower{0.0}, upper{0.0};  // bounding box of all spheres (zero when there are none)
    std::vector<Diagnostic> warnings;  // the parser's, then lights inside spheres, spheres behind the camera
    std::string json(const Scene& scene) const;
    std::string text(const Scene& scene) const;
};

// `path`: the scene's file, for the warnings' locations.
SceneReport checkScene(const Scene& scene, const std::string& path);

}  // namespace snell
