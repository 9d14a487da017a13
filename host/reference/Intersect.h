// Ray–sphere intersection in double precision: the CPU reference's half of the
// intersector whose float twin is in shaders/trace.comp.
//
// Roots follow Haines et al., "Precision Improvements for Ray/Sphere
// Intersection" (Ray Tracing Gems, ch. 7): the discriminant from the
// perpendicular vector (no b² − c cancellation) and the q-form roots (no
// −b ± √Δ cancellation). Self-intersection (SPEC §5) needs no epsilon: a ray
// that starts on a sphere's surface either leaves the convex sphere (that
// sphere cannot be hit again) or enters it, and then its only hit is the exact
// chord root t = −2 (o·d)/(d·d), the non-zero root when o is on the surface.
// A ray that starts within rounding distance of *another* sphere's surface (a
// hit point on a touching or overlapping sphere) is taken to start just
// outside it: it hits it at t = 0 if it heads in (o·d < 0) and misses it if it
// heads out. The hit point lies on the closest surface along its ray, so in
// exact arithmetic it is outside every sphere it did not hit; only rounding can
// put it inside, and then the sign of |o|² − 1 is noise that would speckle the
// seams of overlapping spheres with false shadows.
#pragma once

#include <cmath>
#include <limits>

#include <glm/glm.hpp>

namespace snell {

struct Ray {
    glm::dvec3 origin;
    glm::dvec3 direction;  // unit length
};

// How a ray relates to a sphere whose surface it starts on.
enum class StartsOn { Elsewhere, Leaving, Entering };

inline constexpr double kNoHit = std::numeric_limits<double>::infinity();
// Four units of double rounding: the band around a surface within which a ray
// origin counts as on it.
inline constexpr double kRounding = 4.0 * std::numeric_limits<double>::epsilon() / 2.0;

// Smallest root t > 0 of |o + t d|^2 = 1 for the unit sphere, given o and d in
// the sphere's own frame (d not necessarily unit); kNoHit if none.
// `tolerance`: how far (object units) rounding may have put o off the surface.
inline double intersectUnitSphere(const glm::dvec3& o, const glm::dvec3& d, StartsOn start, double tolerance = 0.0) {
    const double a = glm::dot(d, d);
    const double b = glm::dot(o, d);
    if (start == StartsOn::Leaving) return kNoHit;
    if (start == StartsOn::Entering) {
        const double chord = -2.0 * b / a;
        return chord > 0.0 ? chord : kNoHit;
    }
    const glm::dvec3 perpendicular = o - (b / a) * d;
    const double discriminant = a * (1.0 - glm::dot(perpendicular, perpendicular));
    if (discriminant < 0.0) return kNoHit;
    if (std::abs(glm::length(o) - 1.0) <= tolerance) return b < 0.0 ? 0.0 : kNoHit;
    const double q = -(b + std::copysign(std::sqrt(discriminant), b));
    if (q == 0.0) return kNoHit;
    const double c = glm::dot(o, o) - 1.0;
    double t0 = c / q, t1 = q / a;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > 0.0) return t0;
    if (t1 > 0.0) return t1;
    return kNoHit;
}

// The same for a true sphere (centre, radius) and a unit direction: the unit
// sphere's equation scaled by r, so a = 1 and o is relative to the centre.
inline double intersectSphere(const glm::dvec3& centre, double radius, const Ray& ray, StartsOn start) {
    const double tolerance = kRounding * (glm::length(ray.origin) + glm::length(centre) + radius);
    const glm::dvec3 f = ray.origin - centre;
    const double b = glm::dot(f, ray.direction);
    if (start == StartsOn::Leaving) return kNoHit;
    if (start == StartsOn::Entering) {
        const double chord = -2.0 * b;
        return chord > 0.0 ? chord : kNoHit;
    }
    const glm::dvec3 perpendicular = f - b * ray.direction;
    const double discriminant = radius * radius - glm::dot(perpendicular, perpendicular);
    if (discriminant < 0.0) return kNoHit;
    if (std::abs(glm::length(f) - radius) <= tolerance) return b < 0.0 ? 0.0 : kNoHit;
    const double q = -(b + std::copysign(std::sqrt(discriminant), b));
    if (q == 0.0) return kNoHit;
    const double c = glm::dot(f, f) - radius * radius;
    double t0 = c / q, t1 = q;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > 0.0) return t0;
    if (t1 > 0.0) return t1;
    return kNoHit;
}

// Snell's law in the vector form of SPEC §4.5: for unit D and the shading
// normal N (N·D < 0), eta = eta_i/eta_t. Returns false on total internal
// reflection (k < 0); else sets `refracted` (unit).
inline bool refractDirection(const glm::dvec3& d, const glm::dvec3& n, double eta, glm::dvec3& refracted) {
    const double c = -glm::dot(n, d);  // N·V
    const double k = 1.0 - eta * eta * (1.0 - c * c);
    if (k < 0.0) return false;
    refracted = glm::normalize(eta * d + (eta * c - std::sqrt(k)) * n);
    return true;
}

inline glm::dvec3 reflectDirection(const glm::dvec3& d, const glm::dvec3& n) {
    return d - 2.0 * glm::dot(d, n) * n;
}

}  // namespace snell
