#include "scene/Scene.h"

#include <algorithm>

namespace snell {

std::string Diagnostic::format(const char* severity) const {
    return location.file + ":" + std::to_string(location.line) + ":" +
           std::to_string(location.column) + ": " + severity + ": " + message;
}

std::size_t Scene::ellipsoidCount() const {
    return static_cast<std::size_t>(std::count_if(
        spheres.begin(), spheres.end(), [](const Sphere& s) { return !s.isTrueSphere; }));
}

std::size_t Scene::refractiveSphereCount() const {
    return static_cast<std::size_t>(std::count_if(
        spheres.begin(), spheres.end(),
        [this](const Sphere& s) { return materials[s.material].refracts(); }));
}

bool Scene::anyReflection() const {
    return std::any_of(spheres.begin(), spheres.end(),
                       [this](const Sphere& s) { return materials[s.material].reflects(); });
}

bool Scene::anyRefraction() const { return refractiveSphereCount() > 0; }

Camera Camera::fromSpec(int imageSize, double halfWidth) {
    // SPEC §3: P(x, y) = (-d + x*2d/n, d - y*2d/n, 0), eye E = (0, 0, 1).
    Camera c;
    c.eye = dvec3(0.0, 0.0, 1.0);
    c.forward = dvec3(0.0, 0.0, -1.0);
    c.cornerDir = dvec3(-halfWidth, halfWidth, -1.0);
    const double step = 2.0 * halfWidth / imageSize;
    c.pixelRight = dvec3(step, 0.0, 0.0);
    c.pixelDown = dvec3(0.0, -step, 0.0);
    return c;
}

}  // namespace snell
