// 4–5. One hit's children (SPEC §4.4, §4.5): the reflected ray, which keeps
// the medium stack, and the refracted ray by Snell's law, unless total
// internal reflection folds its weight into the reflected one. Pure: which
// child is traced next, waits or is lost is the scheduler's
// (schedule/tree.glsl, followChildren).
#ifndef SNELL_PHYSICS_CHILDREN_GLSL
#define SNELL_PHYSICS_CHILDREN_GLSL

struct Children {
    Ray reflected;   // its weight holds the transmitted one under total internal reflection
    Ray refracted;   // where transmits; its medium stack the parent's crossed at the hit
                     // (crossSurface with removeAt, applied where it is traced or stored)
    bool transmits;  // a refracted ray exists (no total internal reflection)
    bool undecided;  // total internal reflection or not is within its margin (margins.glsl)
    uint removeAt;   // leaving a sphere: where it is in the parent's medium stack (relativeIndex)
};

// The gain of hit h's children together: ks reflected, kt transmitted.
vec3 childrenGain(Hit h) {
    vec3 reflectedGain = HAS_REFLECTION ? h.ks.rgb : vec3(0.0);
    return reflectedGain + (HAS_REFRACTION ? h.kt.rgb : vec3(0.0));
}

// The children of ray r, carrying `weight`, at hit h. Their weights are
// capped at MAX_WEIGHT.
Children children(Ray r, vec3 weight, Hit h) {
    Children c;
    rvec3 d = r.dir;
    rvec3 n = h.normal;
    vec3 reflectedGain = HAS_REFLECTION ? h.ks.rgb : vec3(0.0);
    vec3 reflectedWeight = min(weighted(weight, reflectedGain), vec3(MAX_WEIGHT));
    c.transmits = false;
    c.undecided = false;
    rvec3 refracted = rvec3(0.0);
    rvec2 refractedOff = rvec2(0.0);
    vec3 transmittedWeight = vec3(0.0);
    c.removeAt = r.mediaCount;
    // What both children inherit of the ray's and the hit's offsets
    // (margins.glsl); nothing under a covered ray (physics/hit.glsl, findHit).
    real normalOff = 0.0;
    rvec2 handed = rvec2(0.0);
    if (DECISIONS && !r.covered)
        handed = handedDown(r.off, h.pointOff, h.distance, h.rounding, h.turning, h.fromOutside, normalOff);
    vec4 kt = h.kt;
    if (HAS_REFRACTION && max(kt.r, max(kt.g, kt.b)) > 0.0) {
        transmittedWeight = min(weighted(weight, kt.rgb), vec3(MAX_WEIGHT));
        // Snell's law, SPEC §4.5.
        real eta = relativeIndex(r, h, c.removeAt);
        real cosIncident = -dot(n, d);
        real k = 1.0 - eta * eta * (1.0 - cosIncident * cosIncident);
        if (DECISIONS) c.undecided = abs(k) <= reflectionMargin(eta, r.off.y + h.normalOff);
        if (k < 0.0) {
            // Total internal reflection is the reflected ray in the same medium:
            // one ray carries both weights.
            reflectedWeight = min(reflectedWeight + transmittedWeight, vec3(MAX_WEIGHT));
        } else {
            c.transmits = true;
            real root = sqrt(k);
            refracted = normalize(eta * d + (eta * cosIncident - root) * n);
            if (DECISIONS) refractedOff = refractedOffset(handed, normalOff, eta, root);
        }
    }
    rvec2 reflectedOff = DECISIONS ? reflectedOffset(handed, normalOff) : rvec2(0.0);
    c.reflected = Ray(h.point, d - 2.0 * dot(d, n) * n, reflectedWeight, r.depth + 1u, h.sphere, !h.fromOutside,
                      r.mediaCount, 0u, reflectedOff, r.covered);
    c.refracted = Ray(h.point, refracted, transmittedWeight, r.depth + 1u, h.sphere, h.fromOutside, r.mediaCount, 0u,
                      refractedOff, r.covered);
    return c;
}

#endif
