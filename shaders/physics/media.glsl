// SPEC §4.5's medium stack: the refractive index a refracted ray sees, and
// the stack it carries on. The stack of the ray in hand is `media`
// (physics/ray.glsl), in registers; crossSurface updates it in place.
#ifndef SNELL_PHYSICS_MEDIA_GLSL
#define SNELL_PHYSICS_MEDIA_GLSL

float etaOfSphere(uint sphere) { return materialKt(sphereMaterial(sphere)).w; }

// The refractive index of the medium ray r travels in over that of the
// medium it refracts into at hit h (SPEC §4.5, the medium stack). Leaving a
// sphere, removeAt is where it is in the stack (its innermost occurrence;
// r.mediaCount where absent: nothing is removed); entering, it is unchanged.
real relativeIndex(Ray r, Hit h, inout uint removeAt) {
    if (h.fromOutside) {
        // Entering: from the current medium into this sphere.
        return (r.mediaCount == 0u ? frame.airEta : etaOfSphere(mediumAt(r.mediaCount - 1u))) / real(h.kt.w);
    }
    // Leaving: into the medium that remains once this sphere is removed.
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k)
        if (uint(k) < r.mediaCount && media[k] == h.sphere) removeAt = uint(k);
    uint innermost = NONE;  // the innermost one that stays
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k)
        if (uint(k) < r.mediaCount && uint(k) != removeAt) innermost = media[k];
    return real(h.kt.w) / (innermost == NONE ? frame.airEta : etaOfSphere(innermost));
}

// The medium stack (`media`, `count` entries) of a ray refracted at hit h:
// entering, the sphere is pushed (a stack deeper than the scene can nest
// forgets its outermost); leaving, entry removeAt is removed. Returns the new
// count.
uint crossSurface(Hit h, uint count, uint removeAt) {
    if (h.fromOutside) {
        if (count == uint(MAX_MEDIA)) {
            [[unroll]] for (int k = 0; k + 1 < MAX_MEDIA; ++k) media[k] = media[k + 1];
            count--;
        }
        [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k)
            if (uint(k) == count) media[k] = h.sphere;
        return count + 1u;
    }
    if (removeAt < count) {
        [[unroll]] for (int k = 0; k + 1 < MAX_MEDIA; ++k)
            if (uint(k) >= removeAt && uint(k) + 1u < count) media[k] = media[k + 1];
        count--;
    }
    return count;
}

#endif
