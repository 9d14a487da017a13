// Ray–sphere intersection in the shader's precision (precision.glsl, float32
// unless SNELL_FP64): the shader's half of the intersector
// whose double twin is host/reference/Intersect.h (which explains the maths).
// Pure functions of their arguments, included by trace.comp and by the test
// kernel intersect_kernel.comp.
//
// Roots: Haines et al., "Precision Improvements for Ray/Sphere Intersection"
// (Ray Tracing Gems ch. 7), the discriminant from the perpendicular vector and
// the q-form roots. Self-intersection (SPEC §5) without an epsilon: a ray that
// starts on a sphere and leaves it cannot hit it again; one that enters it hits
// it at the exact chord root. A ray that starts within rounding distance of
// another sphere's surface (a hit point on a touching or overlapping sphere)
// starts just outside it: it hits it at once if it heads in, misses it if it
// heads out; without that rule the sign of |f|² − r² is noise there and the
// seams of overlapping spheres come out speckled.
#ifndef SNELL_INTERSECT_GLSL
#define SNELL_INTERSECT_GLSL
#include "precision.glsl"
#include "physics/margins.glsl"

const real NO_HIT = 3.0e38;
// How a ray relates to a sphere it may start on.
const uint ELSEWHERE = 0u;
const uint LEAVING = 1u;
const uint ENTERING = 2u;

const real ROUNDING = 4.0 * UNIT_ROUNDOFF;  // 4 units of rounding
const real SQRT3 = 1.7320509;  // √3, rounded up

real rootsToHit(real b, real a, real c, real rootDiscriminant) {
    // q-form: q = −(b + sign(b)·√Δ); roots c/q and q/a, no cancellation.
    real q = -(b + (b >= 0.0 ? rootDiscriminant : -rootDiscriminant));
    if (q == 0.0) return NO_HIT;
    real t0 = c / q;
    real t1 = q / a;
    real near = min(t0, t1);
    real far = max(t0, t1);
    return near > 0.0 ? near : (far > 0.0 ? far : NO_HIT);
}

// How sure a crossing is (margins.glsl; host/render/Margins.h derives it).
// Misses are the common case, and most are sure: past the surface by more
// than the ray's offset may be (a radius widened by a bound on it, the
// sphere's `reach`), they leave the intersector at once (a branch, taken
// where every lane of a SIMD row misses). The widened test is a shortcut the
// CPU reference does without: it passes on every near miss the exact test
// below would find, and more, so no answer changes. A near miss, rare, is
// behind a branch kept as one: closest to the centre at t = closest, it may
// be a hit about there (nearMissFrom).
bool surelyMissed(real reach, real across) {
    // Widened by 16 units of rounding: the two tests' own rounding.
    real widened = reach * (1.0 + 16.0 * UNIT_ROUNDOFF);
    return widened * widened - across < 0.0;
}
real sureMiss() {
    crossingRival = NO_HIT;
    crossingGrazing = false;
    return NO_HIT;
}
void crossingMissed(real closest, real radius, real off, real discriminant) {
    real decides = discriminantMargin(radius, off);
    crossingGrazing = false;
    crossingRival = discriminant + decides > 0.0 && closest + off > 0.0 ? nearMissFrom(closest, decides, off) : NO_HIT;
}
// Otherwise the margins are worked out once, whichever case the intersector
// took (entering at the chord, within rounding of the surface, or the roots),
// so that a SIMD row whose lanes took different cases pays for one. The
// crossing t (NO_HIT: none) of a sphere of radius `radius` (1 in an
// ellipsoid's frame), found at half-chord halfChord, `off` how far the ray may
// be from the exact one there; `along` turns the frame's distances into the
// ray's parameter (1/|d|). Within rounding of the surface (`near`) the ray
// may be on either side of it.
void crossingFound(real t, real radius, real halfChord, real off, real discriminant, real along, bool entering,
                   bool near) {
    crossingMargin = hitMargin(radius, halfChord, off) * along;
    bool found = t < NO_HIT;
    crossingGrazing = found && (near || (entering ? t <= crossingMargin : discriminant <= discriminantMargin(radius, off)));
    crossingRival = near ? 0.0 : found ? t - crossingMargin : NO_HIT;
}

// How far across itself objectFromWorld (m) moves the ray's line for a world
// offset of 1 (Margins.h, acrossStretch), u the unit direction in its frame.
real acrossStretch(rmat3 m, rvec3 u) {
    real sum = 0.0;
    for (int column = 0; column < 3; ++column) {
        rvec3 across = m[column] - dot(u, m[column]) * u;
        sum += dot(across, across);
    }
    return sqrt(sum);
}

// The unit sphere seen through objectFromWorld (an ellipsoid). matrixNorm is
// the largest absolute row sum of its linear part, originLength |origin|: the
// scales of the rounding in o (prepared once per ellipsoid and per ray).
real intersectEllipsoid(rmat4 objectFromWorld, real matrixNorm, rvec3 origin, real originLength, rvec3 dir,
                        uint mode) {
    rvec3 o = (objectFromWorld * rvec4(origin, 1.0)).xyz;
    rvec3 d = rmat3(objectFromWorld) * dir;
    real a = dot(d, d);
    real b = dot(o, d);
    real lengthO = length(o);
    rvec3 perpendicular = o - (b / a) * d;
    real across = dot(perpendicular, perpendicular);
    real discriminant = a * (1.0 - across);
    bool entering = mode == ENTERING;
    // The margins (crossUnitSphere in host/reference/Intersect.h): how far the
    // line may be from the exact one's in this frame near t, from the world's
    // offset there, which also moves the hit along the ray.
    real closest = -b / a;
    real own = CHAIN * UNIT_ROUNDOFF * (lengthO + 1.0);
    // A sure miss: √3 matrixNorm bounds acrossStretch (by the matrix's
    // Frobenius norm), sparing its square roots. `world`: the world's offset
    // at the closest approach (at the crossing, once one is found).
    real world = DECISIONS ? offAt(searchOff, max(closest, 0.0), originLength) : 0.0;
    if (mode == LEAVING || (!entering && surelyMissed(1.0 + SQRT3 * matrixNorm * world + own, across)))
        return sureMiss();
    real lengthD = DECISIONS ? sqrt(a) : 1.0;
    [[dont_flatten]] if (!entering && discriminant < 0.0) {
        if (DECISIONS) {
            real off = acrossStretch(rmat3(objectFromWorld), d / lengthD) * world + own;
            crossingMissed(closest * lengthD, 1.0, off, discriminant / a);
            if (crossingRival < NO_HIT) crossingRival /= lengthD;
        }
        return NO_HIT;
    }
    // Rounding of o: of the origin through the matrix, and of the product.
    bool near = !entering && abs(lengthO - 1.0) <= ROUNDING * (lengthO + 1.0 + matrixNorm * originLength);
    real root = sqrt(max(discriminant, 0.0));
    real t;
    if (entering) t = 2.0 * closest > 0.0 ? 2.0 * closest : NO_HIT;  // the chord
    else if (near) t = b < 0.0 ? 0.0 : NO_HIT;
    else t = rootsToHit(b, a, dot(o, o) - 1.0, root);
    if (DECISIONS) {
        if (t < NO_HIT) world = offAt(searchOff, t, originLength);
        real off = acrossStretch(rmat3(objectFromWorld), d / lengthD) * world + own;
        crossingFound(t, 1.0, (entering ? abs(b) : root) / lengthD, off, discriminant / a, 1.0 / lengthD, entering, near);
        crossingMargin += world;
        if (t < NO_HIT && !near) crossingRival = t - crossingMargin;
        if (entering) crossingGrazing = t < NO_HIT && t <= crossingMargin;
    }
    return t;
}

// A true sphere stored by its anchor (shared_layout.h): the surface point P0
// (anchorRadius.xyz), the outward normal n0 there (normal.xyz) and the radius
// (anchorRadius.w); normal.w is |P0|, originLength |origin|.
// With g = o − P0, f = o − centre = g + r n0 and c = |f|² − r² = |g|² + 2r n0·g.
real intersectTrueSphere(rvec4 anchorRadius, rvec4 normal, rvec3 origin, real originLength, rvec3 dir, uint mode) {
    rvec3 n0 = normal.xyz;
    rvec3 g = origin - anchorRadius.xyz;
    real r = anchorRadius.w;
    real b = dot(g, dir) + r * dot(n0, dir);
    // The rounding of g = o − P0 (the anchor keeps it near the surface): the
    // scale of the point's and of t's rounding, however large the sphere.
    real scale = originLength + normal.w;
    rvec3 f = g + r * n0;
    rvec3 perpendicular = f - b * dir;
    real across = dot(perpendicular, perpendicular);
    real discriminant = r * r - across;
    bool entering = mode == ENTERING;
    if (mode == LEAVING || (!entering && surelyMissed(r + searchReach, across))) return sureMiss();
    [[dont_flatten]] if (!entering && discriminant < 0.0) {
        // offAt at the closest approach.
        if (DECISIONS) crossingMissed(-b, r, offAt(searchOff, max(-b, 0.0), scale), discriminant);
        return NO_HIT;
    }
    real c = dot(g, g) + 2.0 * r * dot(n0, g);
    // Within rounding of the surface: |c| / (|f| + r) (the distance to it) is
    // at most the rounding of g = o − P0, whose operands' scale bounds |g| too:
    // |o| + |P0| + |g| <= 2 (|o| + |P0|). No division, one square root.
    bool near = !entering && abs(c) <= 2.0 * ROUNDING * scale * (length(f) + r);
    real root = sqrt(max(discriminant, 0.0));
    real t;
    if (entering) t = -2.0 * b > 0.0 ? -2.0 * b : NO_HIT;  // the chord
    else if (near) t = b < 0.0 ? 0.0 : NO_HIT;
    else t = rootsToHit(b, 1.0, c, root);
    if (DECISIONS) {
        real off = offAt(searchOff, t < NO_HIT ? t : max(-b, 0.0), scale);
        crossingFound(t, r, entering ? abs(b) : root, off, discriminant, 1.0, entering, near);
    }
    return t;
}

#endif
