// The margins of the decisions rounding can flip (docs/decisions.md). A
// computed ray stands for an exact one of SPEC §4's tree; it may be off by
// `spread` at its origin (world units) and by `tilt` in its direction
// (radians), from the rounding of every step before it. A decision (which
// sphere is nearer, hit or miss, inside or outside, total internal
// reflection, a shadow ray blocked) is *undecided* when the exact ray's
// answer could differ: when the quantity it tests is within its margin of
// the boundary. First-order forward error analysis (Higham, "Accuracy and
// Stability of Numerical Algorithms", ch. 3), each operation chain rounding
// at most kChain units; `unit` is the unit roundoff of the arithmetic (2^-53
// for double, 2^-24 for float). The twin for the shader is
// shaders/physics/margins.glsl: the same formulas, the same names.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace snell::margins {

// Units of rounding an operation chain of the intersector or of shading may
// take (a dot product of three terms and what follows it, with room).
inline constexpr double kChain = 4.0;

// How far a computed ray may be from the exact one.
struct Uncertainty {
    double spread = 0.0;  // of its origin, world units
    double tilt = 0.0;    // of its direction, radians
};

// How far the point at parameter t of the ray may be from the exact ray's:
// its origin's and direction's uncertainty, and the rounding of o + t·d and
// of the sphere data at `scale` (|o| + |sphere| + size).
inline double offAt(const Uncertainty& u, double t, double scale, double unit) {
    return u.spread + u.tilt * t + kChain * unit * (scale + t);
}

// Hit or miss. A sphere of radius r (a unit sphere in object space for an
// ellipsoid) is met when the ray passes within r of its centre: with the ray
// off by `off` the perpendicular distance p may be off as much, so the
// discriminant r² − p² = (r − p)(r + p) decides only beyond (2r + off)·off.
inline double discriminantMargin(double radius, double off) { return (2.0 * radius + off) * off; }

// Nearest hit. A hit of half-chord h on a sphere of radius r meets the surface
// at an angle whose cosine is h/r: the ray offset by `off` meets it up to
// off·r/h from the computed point, along the surface's normal over its cosine.
inline double hitMargin(double radius, double halfChord, double off) { return off * radius / halfChord; }

// Hit or miss, the other way: a near miss (its discriminant within the margin
// above, `decides`) may be a hit of the exact ray, whose half-chord is then at
// most √decides: no sooner than the closest approach less that and the offset.
inline double nearMissFrom(double closest, double decides, double off) {
    return std::max(0.0, closest - std::sqrt(decides) - off);
}

// Inside or outside (SPEC §4.2): the sign of D·No, with D off by `tilt` and No
// by `normalOff`.
inline double facingMargin(double tilt, double normalOff, double unit) { return tilt + normalOff + kChain * unit; }

// Total internal reflection (SPEC §4.5): the sign of k = 1 − η²(1 − c²), c =
// N·V off by `cosineOff`: k moves by 2η²c·Δc (c ≤ 1), and rounds.
inline double reflectionMargin(double eta, double cosineOff, double unit) {
    return 2.0 * eta * eta * cosineOff + kChain * unit * (1.0 + eta * eta);
}

// How far Phong's specular factor (R·V)^p (0 where R·V <= 0, SPEC §4.3) may
// be from the exact one, with R·V = rv off by `cosineOff` = δ and `specular`
// the factor computed from rv. The factor grows with R·V, so the exact one
// lies between the ends' values. With x = δ/rv: above, (1 + x)^p <= e^(px)
// (log(1 + x) <= x), which is within specular·px(1 + px) while px < 1/2 (the
// slope p·rv^(p−1)·δ understates it beyond); past that, the upper end's value
// itself, (rv + δ)^p, bounds the move. Below, by at most specular·max(p, 1)·x
// (Bernoulli; (1 − x)^p >= 1 − x for p < 1). Never more than 1: the exact
// factor lies in [0, 1]. `logOff`: the absolute error the arithmetic allows
// log2 near 1 (0 for the CPU's pow; 2^-21 in Vulkan), which p multiplies.
inline double specularOff(double rv, double p, double cosineOff, double specular, double logOff) {
    const double top = rv + cosineOff;
    const double x = cosineOff / rv, a = p * (x + logOff);
    if (!(rv > 0.0) || !(a < 0.5))
        return top > 0.0 ? std::min(1.0, std::pow(std::min(top, 1.0), p) * std::exp2(p * logOff) * (1.0 + 1e-10)) : 0.0;
    return std::min(1.0, specular * std::max(a * (1.0 + a), std::min(1.0, std::max(p, 1.0) * x)));
}

// How far a hit's outward normal may be off: the hit point's offset times how
// fast the normal turns there (1/r on a true sphere; CpuRenderer::outwardNormal).
inline double normalOff(double pointOff, double curvature, double unit) { return pointOff * curvature + kChain * unit; }

// What a hit's children inherit: the point's offset, and the direction's
// tilt turned by the normal's. The normal turns with the whole offset of the
// point where the ray meets the surface from outside, a convex surface, which
// spreads neighbouring rays apart (a mirror ball by 1 + 2t/r a bounce: chains
// of them, sphereflakes, diverge). From inside, a concave surface focuses
// them back, and a bound that adds magnitudes cannot see that: carried through
// every bounce of an orbit inside a sphere, it would compound until after a
// few dozen bounces it said "anything". There the normal turns with the
// point's own rounding only: a first-order model, not a bound on long orbits
// (docs/decisions.md).
// Inside, the origin's offset is carried along the ray as it is (not
// amplified by the angle the ray meets the surface at either).
// `offset`: the point's whole offset (Closest::margin and rounding); t: the
// hit's distance; `rounding`: the point's own rounding.
struct Hand {
    double offset, t, rounding, turning;
    bool convex;
};
inline Uncertainty handedDown(const Uncertainty& parent, const Hand& h, double unit, double& normal) {
    normal = normalOff(h.convex ? h.offset : h.rounding, h.turning, unit);
    return {h.convex ? h.offset : parent.spread + parent.tilt * h.t + h.rounding, parent.tilt};
}
// Reflection R = D − 2(D·N)N turns with D and twice with N.
inline Uncertainty reflected(const Uncertainty& parent, const Hand& h, double unit) {
    double normal = 0.0;
    Uncertainty u = handedDown(parent, h, unit, normal);
    u.tilt += 2.0 * normal + kChain * unit;
    return u;
}
// Refraction T = ηD + (ηc − √k)N (SPEC §4.5): ∂T/∂D ≈ η, and through c and
// √k (∂√k/∂c = η²c/√k) the normal moves it by up to (η + η²/√k).
inline Uncertainty refracted(const Uncertainty& parent, const Hand& h, double eta, double k, double unit) {
    double normal = 0.0;
    Uncertainty u = handedDown(parent, h, unit, normal);
    u.tilt = eta * parent.tilt + (eta + eta * eta / std::sqrt(k)) * normal + kChain * unit;
    return u;
}

// How fast the normal n = A x of the quadric xᵀ A x = 1 (A = Mᵀ M) turns as x
// moves: A δ turns it by the part of A δ across n, over |n|:
// ‖(I − N Nᵀ) A‖ δ / |n|, the norm bounded by Frobenius'.
inline double turning(const glm::dmat3& a, const glm::dvec3& n) {
    const double length = glm::length(n);
    const glm::dvec3 unit = n / length;
    double sum = 0.0;
    for (int column = 0; column < 3; ++column) {
        const glm::dvec3 across = a[column] - glm::dot(unit, a[column]) * unit;
        sum += glm::dot(across, across);
    }
    return std::sqrt(sum) / length;
}

// How much an ellipsoid's object frame (M = objectFromWorld) may move the
// ray's line across itself when the world ray is offset by 1: the part of M δ
// across the line's object direction u = M d / |M d|, at most
// ‖(I − u uᵀ) M‖ (Frobenius). An offset along the line moves no hit on or off.
// (The largest stretch of M itself, 1/thickness for a flat ellipsoid, would
// call every hit of a thin disc undecided.)
inline double acrossStretch(const glm::dmat3& m, const glm::dvec3& objectDir) {
    const glm::dvec3 u = objectDir / glm::length(objectDir);
    double sum = 0.0;
    for (int column = 0; column < 3; ++column) {
        const glm::dvec3 across = m[column] - glm::dot(u, m[column]) * u;
        sum += glm::dot(across, across);
    }
    return std::sqrt(sum);
}
}  // namespace snell::margins
