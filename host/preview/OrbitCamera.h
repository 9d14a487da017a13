// The preview's camera: starts as the scene's (SPEC §3) and orbits around a
// pivot, the point the camera looks at (where its central ray first meets a
// sphere's bounds, else the scene's centre); pans the pivot in the image
// plane; zooms by moving towards it. No Vulkan, no window: unit-tested.
#pragma once

#include "scene/Scene.h"

namespace snell {

class OrbitCamera {
public:
    OrbitCamera() = default;
    OrbitCamera(const Scene& scene, const Camera& home, double halfWidth);

    // Drag by (dx, dy) pixels of a window `size` pixels across.
    void orbit(double dx, double dy, double size);
    void pan(double dx, double dy, double size);
    // Positive steps move closer.
    void zoom(double steps);
    // Orbit about the vertical axis by `degrees` (the scripted mode's --orbit).
    void orbitDegrees(double degrees);
    void reset();
    bool atHome() const { return atHome_; }

    // The camera for an image of width × height pixels; the scene's own camera,
    // exactly, when nothing has moved.
    Camera camera(int width, int height) const;
    const dvec3& pivot() const { return pivot_; }

private:
    Camera home_;
    double halfWidth_ = 0.5;
    dvec3 forward_{0, 0, -1}, right_{1, 0, 0}, up_{0, 1, 0};
    dvec3 homePivot_{0.0}, pivot_{0.0};
    double homeDistance_ = 1.0, distance_ = 1.0;
    double yaw_ = 0.0, pitch_ = 0.0;  // radians, about up_ and the camera's right
    bool atHome_ = true;
};

// How far along `direction` from `eye` the view first meets a sphere's bounds
// (its centre's distance when the eye is inside one); the distance to the
// scene's centre when it meets none; 1 in an empty scene.
double pivotDistance(const Scene& scene, const dvec3& eye, const dvec3& direction);

}  // namespace snell
