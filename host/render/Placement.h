// How two spheres lie against each other, judged by bounding balls: what the
// analyses of render/Truncation.cpp and render/Reach.cpp ask of a scene's
// geometry without tracing a ray.
#pragma once

#include <cmath>

#include "scene/Scene.h"

namespace snell {

// A ball that holds a sphere or an ellipsoid: itself, or a centre and the
// Frobenius norm of the linear part (at least its longest semi-axis).
struct Ball {
    glm::dvec3 centre{0.0};
    double radius = 0.0;
};
inline Ball boundingBall(const Sphere& s) {
    if (s.isTrueSphere) return {s.centre, s.radius};
    double squares = 0.0;
    for (int c = 0; c < 3; ++c) squares += glm::dot(glm::dvec3(s.worldFromObject[c]), glm::dvec3(s.worldFromObject[c]));
    return {glm::dvec3(s.worldFromObject[3]), std::sqrt(squares)};
}

// How ball a lies against ball b: inside it, around it, apart, or their
// surfaces cross (or touch, within rounding: treated as crossing).
enum class Placement { Inside, Around, Apart, Crossing };
inline Placement placement(const Ball& a, const Ball& b) {
    const double d = glm::length(a.centre - b.centre);
    const double margin = 1e-9 * (d + a.radius + b.radius);
    if (d + a.radius < b.radius - margin) return Placement::Inside;
    if (d + b.radius < a.radius - margin) return Placement::Around;
    if (d > a.radius + b.radius + margin) return Placement::Apart;
    return Placement::Crossing;
}

// Whether ball b holds the point, or nearly, as rounding has it.
inline bool holds(const Ball& b, const glm::dvec3& point) {
    return glm::length(point - b.centre) <= b.radius * (1.0 + 1e-9);
}

}  // namespace snell
