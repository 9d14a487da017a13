// The margins of the decisions rounding can flip: the twin of
// host/render/Margins.h, which derives them (the same formulas, in the
// shader's precision: UNIT_ROUNDOFF). A ray carries how far it may be from
// the exact ray of SPEC §4's tree (Ray.off: the spread of its origin, the tilt
// of its direction); a decision within its margin is undecided, and the light
// of the pixel that hangs on it is reported (SlotState.undecided).
#ifndef SNELL_PHYSICS_MARGINS_GLSL
#define SNELL_PHYSICS_MARGINS_GLSL

// Off: no margins kept (the test kernels, and a kernel that measures their cost).
layout(constant_id = SNELL_SPEC_DECISIONS) const bool DECISIONS = false;

const real CHAIN = 4.0;  // units of rounding an operation chain may take (Margins.h, kChain)

real offAt(rvec2 off, real t, real scale) { return off.x + off.y * t + CHAIN * UNIT_ROUNDOFF * (scale + t); }
real discriminantMargin(real radius, real off) { return (2.0 * radius + off) * off; }
real hitMargin(real radius, real halfChord, real off) { return off * radius / halfChord; }
real nearMissFrom(real closest, real decides, real off) { return max(0.0, closest - sqrt(decides) - off); }
real facingMargin(real tilt, real normalOff) { return tilt + normalOff + CHAIN * UNIT_ROUNDOFF; }
real reflectionMargin(real eta, real cosineOff) {
    return 2.0 * eta * eta * cosineOff + CHAIN * UNIT_ROUNDOFF * (1.0 + eta * eta);
}
// Phong's (R·V)^p off by at most this, R·V = rv off by cosineOff (Margins.h,
// specularOff: within specular·px(1 + px) above while px < 1/2, else the
// upper end's value itself; not the slope, which understates a convex rise).
float specularOffset(float rv, float p, float cosineOff, float specular, float logOff) {
    float x = cosineOff / rv, a = p * (x + logOff);
    bool slope = rv > 0.0 && a < 0.5;
    float offset = slope ? specular * max(a * (1.0 + a), min(1.0, max(p, 1.0) * x)) : 0.0;
    // Rare (R·V within δ of 0, or p·δ/R·V large): a branch, so that rows of
    // lanes with none skip the pow.
    float top = rv + cosineOff;
    [[dont_flatten]] if (!slope && top > 0.0) offset = pow(min(top, 1.0), p) * exp2(p * logOff) * (1.0 + 1e-5);
    return min(1.0, offset);
}
real normalOffset(real pointOff, real turning) { return pointOff * turning + CHAIN * UNIT_ROUNDOFF; }

// How fast the normal n = A x of the quadric xᵀ A x = 1 turns as x moves
// (Margins.h, turning).
real turningOf(rmat3 a, rvec3 n) {
    real size = length(n);
    rvec3 unit = n / size;
    real sum = 0.0;
    for (int column = 0; column < 3; ++column) {
        rvec3 across = a[column] - dot(unit, a[column]) * unit;
        sum += dot(across, across);
    }
    return sqrt(sum) / size;
}

// What a hit's children inherit (Margins.h, handedDown: on a convex surface,
// met from outside, the normal turns with the point's whole offset; inside,
// with its rounding, and the origin's offset is carried along the ray).
// Worked out once for both children; `normal`: the normal's offset.
rvec2 handedDown(rvec2 parent, real offset, real t, real rounding, real turning, bool convex, out real normal) {
    normal = normalOffset(convex ? offset : rounding, turning);
    return rvec2(convex ? offset : parent.x + parent.y * t + rounding, parent.y);
}
// The reflected child's (Margins.h, reflectedOffset), from what is handed down.
rvec2 reflectedOffset(rvec2 handed, real normal) {
    return rvec2(handed.x, handed.y + 2.0 * normal + CHAIN * UNIT_ROUNDOFF);
}
// The refracted child's (Margins.h, refractedOffset), root = √k of Snell's law.
rvec2 refractedOffset(rvec2 handed, real normal, real eta, real root) {
    return rvec2(handed.x, eta * handed.y + (eta + eta * eta / root) * normal + CHAIN * UNIT_ROUNDOFF);
}

// What the intersector learns of the crossing it last returned, beside its t:
// the exact ray's crossing lies within crossingMargin of it; a near miss may
// be a hit from crossingRival on; crossingGrazing: it may be a miss. For the
// ray searchOff (spread, tilt) of the search in progress (hit.glsl).
real crossingMargin;
real crossingRival;
bool crossingGrazing;
rvec2 searchOff;
// The most any true sphere's offset (offAt at its closest approach, scaled by
// its anchor) may be in this search: beyond the radius by more, a miss is
// sure (intersect.glsl). 0 without margins.
real searchReach = 0.0;

#endif
