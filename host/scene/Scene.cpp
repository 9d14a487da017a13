#include "scene/Scene.h"

#include <algorithm>

namespace snell {

std::string Diagnostic::format(const char* severity) const {
    // A problem of the whole file (it cannot be opened) has no position.
    if (location.line <= 0) return location.file + ": " + severity + ": " + message;
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

bool Scene::anyAmplifying() const {
    return std::any_of(materials.begin(), materials.end(), [](const Material& m) { return m.amplifies(); });
}

Camera Camera::fromSpec(int imageSize, double halfWidth) {
    // SPEC §3: P(x, y) = (-d + x*2d/n, d - y*2d/n, 0), eye E = (0, 0, 1).
    return lookAt(dvec3(0.0, 0.0, 1.0), dvec3(0.0), dvec3(0.0, 1.0, 0.0), halfWidth, imageSize, imageSize);
}

Camera Camera::lookAt(const dvec3& eye, const dvec3& target, const dvec3& up, double halfWidth, int width,
                      int height) {
    Camera c;
    c.eye = eye;
    c.forward = glm::normalize(target - eye);
    const dvec3 right = glm::normalize(glm::cross(c.forward, up));
    const dvec3 trueUp = glm::cross(right, c.forward);
    // Square pixels; halfWidth spans the image's width.
    const double step = 2.0 * halfWidth / width;
    const double halfHeight = 0.5 * step * height;
    c.cornerDir = c.forward - halfWidth * right + halfHeight * trueUp;
    c.pixelRight = step * right;
    c.pixelDown = -step * trueUp;
    return c;
}

}  // namespace snell
