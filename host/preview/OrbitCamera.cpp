#include "preview/OrbitCamera.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace snell {

double pivotDistance(const Scene& scene, const dvec3& eye, const dvec3& direction) {
    double nearest = std::numeric_limits<double>::infinity();
    dvec3 lower(std::numeric_limits<double>::infinity()), upper(-std::numeric_limits<double>::infinity());
    for (const Sphere& s : scene.spheres) {
        lower = glm::min(lower, s.centre - s.radius);
        upper = glm::max(upper, s.centre + s.radius);
        const dvec3 f = s.centre - eye;
        const double along = glm::dot(f, direction);
        const double miss2 = glm::dot(f, f) - along * along;
        if (miss2 > s.radius * s.radius) continue;
        const double half = std::sqrt(s.radius * s.radius - miss2);
        const double t = along - half > 0.0 ? along - half : along;  // inside: its centre's depth
        if (t > 0.0) nearest = std::min(nearest, t);
    }
    if (std::isfinite(nearest)) return nearest;
    if (scene.spheres.empty()) return 1.0;
    const double centre = glm::dot(0.5 * (lower + upper) - eye, direction);
    return centre > 0.0 ? centre : std::max(1.0, glm::length(0.5 * (lower + upper) - eye));
}

OrbitCamera::OrbitCamera(const Scene& scene, const Camera& home, double halfWidth)
    : home_(home), halfWidth_(halfWidth) {
    forward_ = home.forward;
    up_ = glm::normalize(-home.pixelDown);
    right_ = glm::normalize(home.pixelRight);
    homeDistance_ = distance_ = pivotDistance(scene, home.eye, forward_);
    homePivot_ = pivot_ = home.eye + homeDistance_ * forward_;
}

void OrbitCamera::orbit(double dx, double dy, double size) {
    const double radiansPerPixel = 3.14159265358979 / std::max(1.0, size);
    yaw_ -= dx * radiansPerPixel;
    pitch_ = std::clamp(pitch_ + dy * radiansPerPixel, -1.55, 1.55);  // never over the pole
    atHome_ = false;
}

void OrbitCamera::orbitDegrees(double degrees) {
    yaw_ += degrees * 3.14159265358979 / 180.0;
    atHome_ = false;
}

void OrbitCamera::pan(double dx, double dy, double size) {
    const Camera c = camera(1, 1);
    const dvec3 right = glm::normalize(c.pixelRight), up = glm::normalize(-c.pixelDown);
    // One window width moves the pivot by the view's width at its distance.
    const double unitsPerPixel = 2.0 * halfWidth_ * distance_ / std::max(1.0, size);
    pivot_ += (-dx * right + dy * up) * unitsPerPixel;
    atHome_ = false;
}

void OrbitCamera::zoom(double steps) {
    distance_ = std::clamp(distance_ * std::pow(0.9, steps), 1e-9 * homeDistance_, 1e9 * homeDistance_);
    atHome_ = false;
}

void OrbitCamera::reset() {
    pivot_ = homePivot_;
    distance_ = homeDistance_;
    yaw_ = pitch_ = 0.0;
    atHome_ = true;
}

Camera OrbitCamera::camera(int width, int height) const {
    // At home: the scene's camera (exactly SPEC §3's for a square image).
    if (atHome_) return Camera::lookAt(home_.eye, home_.eye + forward_, up_, halfWidth_, width, height);
    // The eye on a sphere of radius distance_ about the pivot: yaw about the
    // home up axis, pitch towards it.
    const dvec3 back = -forward_;
    const dvec3 horizontal = std::cos(yaw_) * back + std::sin(yaw_) * right_;
    const dvec3 offset = std::cos(pitch_) * horizontal + std::sin(pitch_) * up_;
    const dvec3 eye = pivot_ + distance_ * offset;
    return Camera::lookAt(eye, pivot_, up_, halfWidth_, width, height);
}

}  // namespace snell
