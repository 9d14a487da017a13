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

#include "render/Margins.h"

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
inline constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2.0;
inline constexpr double kRounding = 4.0 * kUnitRoundoff;

// A ray's crossing of one sphere and how sure it is (Margins.h): the exact
// ray meets it within `margin` of t, not before `rivalFrom` (a near miss may
// be a hit there), and `grazing`: it may miss it altogether.
struct Crossing {
    double t = kNoHit;
    double margin = 0.0;
    double rivalFrom = kNoHit;
    bool grazing = false;
};

// A ray that starts within rounding of a surface it does not start on meets
// it at once if it heads in, and not if it heads out (the header's rule); in
// exact arithmetic the origin may be on either side: undecided.
inline Crossing nearSurface(double b) { return b < 0.0 ? Crossing{0.0, 0.0, 0.0, true} : Crossing{kNoHit, 0.0, 0.0, false}; }

// The crossing of the ray o + t d (object frame; d not unit, so t is the world
// ray's parameter) with the unit sphere. The world ray is off by `uncertainty`
// at world scale `scale`; `stretch` bounds how far across itself
// objectFromWorld moves the line for a world offset of 1 (Margins.h,
// acrossStretch). A hit moves along the ray by the offset across the line over
// the half-chord, and by the offset along it. The cases are the header's:
// leaving, entering (the chord root), within rounding of the surface, the
// q-form roots.
inline Crossing crossUnitSphere(const glm::dvec3& o, const glm::dvec3& d, StartsOn start, double tolerance,
                                const margins::Uncertainty& uncertainty, double stretch, double scale) {
    const double a = glm::dot(d, d);
    const double b = glm::dot(o, d);
    const double length = std::sqrt(a);
    // How far the ray's line may be from the exact one's in this frame, near t;
    // and the world offset there, which moves a hit along the ray.
    auto worldOff = [&](double t) { return margins::offAt(uncertainty, t, scale, kUnitRoundoff); };
    auto offAt = [&](double t) {
        return stretch * worldOff(t) + margins::kChain * kUnitRoundoff * (glm::length(o) + 1.0);
    };
    if (start == StartsOn::Leaving) return {};
    if (start == StartsOn::Entering) {
        const double chord = -2.0 * b / a;
        const double margin =
            margins::hitMargin(1.0, std::abs(b) / length, offAt(std::max(chord, 0.0))) / length + worldOff(chord);
        return chord > 0.0 ? Crossing{chord, margin, chord - margin, chord <= margin} : Crossing{};
    }
    const glm::dvec3 perpendicular = o - (b / a) * d;
    const double discriminant = a * (1.0 - glm::dot(perpendicular, perpendicular));
    if (discriminant < 0.0) {
        const double closest = -b / a;  // a near miss may be a hit about there
        const double off = offAt(std::max(closest, 0.0));
        const double decides = a * margins::discriminantMargin(1.0, off);
        if (discriminant > -decides && closest + off / length > 0.0)
            return {kNoHit, 0.0, margins::nearMissFrom(closest * length, decides / a, off) / length, false};
        return {};
    }
    if (std::abs(glm::length(o) - 1.0) <= tolerance) return nearSurface(b);
    const double q = -(b + std::copysign(std::sqrt(discriminant), b));
    if (q == 0.0) return {};
    const double c = glm::dot(o, o) - 1.0;
    double t0 = c / q, t1 = q / a;
    if (t0 > t1) std::swap(t0, t1);
    const double t = t0 > 0.0 ? t0 : (t1 > 0.0 ? t1 : kNoHit);
    if (t == kNoHit) return {};
    const double off = offAt(t);
    const double margin = margins::hitMargin(1.0, std::sqrt(discriminant / a), off) / length + worldOff(t);
    return {t, margin, t - margin, discriminant <= a * margins::discriminantMargin(1.0, off)};
}

// The same for a true sphere (centre, radius) and a unit direction, the ray
// off by `uncertainty` (world units).
inline Crossing crossSphere(const glm::dvec3& centre, double radius, const Ray& ray, StartsOn start,
                            const margins::Uncertainty& uncertainty) {
    const double scale = glm::length(ray.origin) + glm::length(centre) + radius;
    const double tolerance = kRounding * scale;
    const glm::dvec3 f = ray.origin - centre;
    const double b = glm::dot(f, ray.direction);
    if (start == StartsOn::Leaving) return {};
    if (start == StartsOn::Entering) {
        const double chord = -2.0 * b;
        const double margin =
            margins::hitMargin(radius, std::abs(b), margins::offAt(uncertainty, std::max(chord, 0.0), scale, kUnitRoundoff));
        return chord > 0.0 ? Crossing{chord, margin, chord - margin, chord <= margin} : Crossing{};
    }
    const glm::dvec3 perpendicular = f - b * ray.direction;
    const double discriminant = radius * radius - glm::dot(perpendicular, perpendicular);
    if (discriminant < 0.0) {
        const double off = margins::offAt(uncertainty, std::max(-b, 0.0), scale, kUnitRoundoff);
        const double decides = margins::discriminantMargin(radius, off);
        if (discriminant > -decides && -b + off > 0.0)
            return {kNoHit, 0.0, margins::nearMissFrom(-b, decides, off), false};
        return {};
    }
    if (std::abs(glm::length(f) - radius) <= tolerance) return nearSurface(b);
    const double q = -(b + std::copysign(std::sqrt(discriminant), b));
    if (q == 0.0) return {};
    const double c = glm::dot(f, f) - radius * radius;
    double t0 = c / q, t1 = q;
    if (t0 > t1) std::swap(t0, t1);
    const double t = t0 > 0.0 ? t0 : (t1 > 0.0 ? t1 : kNoHit);
    if (t == kNoHit) return {};
    const double off = margins::offAt(uncertainty, t, scale, kUnitRoundoff);
    const double margin = margins::hitMargin(radius, std::sqrt(discriminant), off);
    return {t, margin, t - margin, discriminant <= margins::discriminantMargin(radius, off)};
}

// Smallest root t > 0 of |o + t d|^2 = 1 for the unit sphere, given o and d in
// the sphere's own frame (d not necessarily unit); kNoHit if none: the crossing
// of an exact ray. `tolerance`: how far (object units) rounding may have put o
// off the surface.
inline double intersectUnitSphere(const glm::dvec3& o, const glm::dvec3& d, StartsOn start, double tolerance = 0.0) {
    return crossUnitSphere(o, d, start, tolerance, {}, 0.0, 0.0).t;
}

// The same for a true sphere (centre, radius) and a unit direction: the unit
// sphere's equation scaled by r, so a = 1 and o is relative to the centre.
inline double intersectSphere(const glm::dvec3& centre, double radius, const Ray& ray, StartsOn start) {
    return crossSphere(centre, radius, ray, start, {}).t;
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
