// A pixel's ray tree (SPEC §4), depth first: which ray is traced next,
// which is admitted under the step's cut-off and the tree budget, and which
// of a hit's children is traced next, waits on the stack, waits in the
// frontier or is lost. The physics of each step is physics/*.glsl's.
#ifndef SNELL_SCHEDULE_TREE_GLSL
#define SNELL_SCHEDULE_TREE_GLSL

// Light that undecided decisions may change (margins.glsl): `amount` is the
// most light of the rays of `weight` whose light either outcome may change
// (rgb), or the light of undecided shadow rays (a). It flags the sample
// (BY_SAMPLE).
void addUndecided(inout SlotState state, vec4 amount, vec3 weight) {
    state.undecided += amount;
    state.undecidedLocal += maxChannel(weighted(weight, frame.localRadiance.rgb));
    if (BY_SAMPLE && (maxChannel(weight) > 0.0 || amount.a > 0.0)) state.sampleFlagged = 1u;
}
// What shading's rounding may have moved of the light added.
void addShadingError(inout SlotState state, float error) {
    state.shading += error;
    if (BY_SAMPLE) state.sampleLight.a += error;
}

// The next ray of the pixel's current step: a child waiting on the stack,
// else a ray the last step left in the frontier, else a camera ray for its
// next sample. False where the step has none left.
bool nextRay(uint slot, inout SlotState state, uvec2 pixel, out Ray ray) {
    if (state.pending > 0u) {
        ray = popRay(slot, state.pending);
        return true;
    }
    if (state.frontierOld > 0u) {
        ray = loadRay(frontierEntry(slot, state.frontierHead));
        state.frontierHead = (state.frontierHead + 1u) % max(FRONTIER, 1u);
        state.frontierCount--;
        state.frontierOld--;
        return true;
    }
    if (state.started < samples) {
        if (BY_SAMPLE && state.started > 0u) closeSample(state);
        ray = cameraRay(imagePixel(pixel), frame.firstSample + state.started);
        state.started++;
        if (COUNT_RAYS) countedRays[SNELL_COUNTER_PRIMARY]++;
        return true;
    }
    return false;
}

// Light ray r returns, added to its pixel. Light the exact tree may not hold
// (a covered ray's, ray.glsl; an undecided shadow ray's, `unsure`) is also
// kept apart, its largest channel (host/gpu/TileReadback.cpp, whiteEitherWay).
void addLight(inout SlotState state, Ray r, vec3 light, bool unsure) {
    state.sum.rgb += light;
    if (BY_SAMPLE) state.sampleLight.rgb += light;
    if (DECISIONS && (r.covered || unsure)) state.unsureLight += maxChannel(light);
}

// Ray r of the pixel, before its closest hit: under the cut-off it waits in
// the frontier, past the tree budget it is lost; else it is traced, with
// `weight` (the channels an amplifying pixel has saturated dropped). A ray
// that resumes shading keeps the weight it started with and is not counted
// twice.
bool admitRay(uint slot, inout SlotState state, inout Ray r, float cutOff, out vec3 weight) {
    weight = r.weight;
    bool resuming = r.resumeShading != 0u;
    if (AMPLIFYING && !resuming) weight = mix(weight, vec3(0.0), greaterThanEqual(state.sum.rgb, vec3(saturation)));
    if (!resuming && !worthTracing(weight, tracingCutOff(state, cutOff))) {
        r.weight = weight;
        deferRay(slot, state, r);
        return false;
    }
    // The pixel's trees past the budget: the rest of them is lost.
    if (!resuming && pixelBudget != 0u && state.treeRays >= pixelBudget) {
        state.overBudget = 1u;
        state.lost.rgb += weighted(weight, rayReach(r));
        return false;
    }
    if (!resuming) {
        state.treeRays++;
        state.rays++;
    }
    return true;
}

// Light carried into a material that traps it (SPEC §4 amplifying materials;
// render/Truncation.h, growthTraps: an orbit of total internal reflection
// that gains at every bounce) grows until its channel saturates, and a path
// of tiny weight that enters one does too. The pixel's series may diverge
// behind steps that seem to settle, so its estimated error must be within
// kAmplifiedEstimate (assessStep) and it goes on below the floor
// (nextCutOff): a hit of such a material, of gain > 1 in a channel where the
// ray carried light, marks the pixel.
void noteGain(inout SlotState state, Hit h, vec3 gain, vec3 weight) {
    if (TRAPS && h.ks.w != 0.0 &&
        any(bvec3(uvec3(greaterThan(gain, vec3(1.0))) & uvec3(greaterThan(weight, vec3(0.0))))))
        state.amplified = 1u;
}

// 4–5. What becomes of the children of ray r (physics/children.glsl) at hit
// h: the depth limit loses their weight (render/Truncation.h); under the
// cut-off a child waits in the frontier (deferRay); of two children one is
// traced next and the other waits on the stack, or is lost where the stack
// is full. Returns whether r is now the child to trace next. Refraction is
// traced first, as in the CPU reference.
bool followChildren(uint slot, inout SlotState state, inout Ray r, vec3 weight, Hit h, float cutOff) {
    vec3 gain = childrenGain(h);
    if (r.depth >= frame.maxDepth) {
        state.lost.rgb += weighted(weighted(weight, gain), frame.radiance.rgb);
        return false;
    }
    noteGain(state, h, gain, weight);
    Children c = children(r, weight, h);
    // Reflected or refracted within the margin: either answer's children
    // carry light within their weights times R (margins.glsl). (Their
    // sphere's reach, read here, made Mesa 22.3 spill the kernel's state to
    // memory it allocates at every dispatch: 40x the time under a loop budget.)
    if (DECISIONS && c.undecided && !r.covered) {
        addUndecided(state, vec4(weighted(weighted(weight, gain), frame.radiance.rgb), 0.0), weighted(weight, gain));
        c.reflected.covered = true;
        c.refracted.covered = true;
    }
    bool reflects = (HAS_REFLECTION || HAS_REFRACTION) && worthTracing(c.reflected.weight, tracingCutOff(state, cutOff));
    if (!reflects && (HAS_REFLECTION || HAS_REFRACTION)) deferRay(slot, state, c.reflected);
    // Asked after the reflected child waits: should it have filled the
    // frontier, the refracted child is traced down to the floor, not lost.
    bool refracts = c.transmits && worthTracing(c.refracted.weight, tracingCutOff(state, cutOff));
    if (reflects && COUNT_RAYS) countedRays[SNELL_COUNTER_REFLECTED]++;
    if (refracts && COUNT_RAYS) countedRays[SNELL_COUNTER_REFRACTED]++;
    if (!c.transmits) {
        r = c.reflected;
        return reflects;
    }
    // Both children: the lighter is traced next and the heavier waits on the
    // stack, so each waiting ray at least halves (ks + kt <= 1) the weight of
    // the path below it, and the stack needs no more than log(cut-off) / log(q)
    // entries however deep the tree (host/gpu/KernelPolicy.cpp sizes it).
    // In an amplifying scene (where the stack is sized by depth anyway) the
    // heavier goes on instead: under a tree budget the weightiest rays are
    // traced first, which is what saturates a diverging channel.
    bool both = reflects && refracts;
    vec3 reflectedWeight = c.reflected.weight, transmittedWeight = c.refracted.weight;
    bool refractedWaits = both && (max(transmittedWeight.r, max(transmittedWeight.g, transmittedWeight.b)) >
                                   max(reflectedWeight.r, max(reflectedWeight.g, reflectedWeight.b))) != AMPLIFYING;
    // One entry stays free for the ray in hand should the invocation suspend.
    // Full (only an amplifying tree can fill it): the child that would wait is
    // lost, its weight counted in the bound, and the host says so.
    bool stackFull = state.pending + 1u >= RAY_STACK;
    if (both && stackFull) {
        atomicAdd(counters[SNELL_COUNTER_OVERFLOW], 1u);
        if (TRAPS) state.droppedGrowing = 1u;  // as on a full frontier (deferRay)
    }
    if (both && !refractedWaits) {
        if (stackFull) state.lost.rgb += weighted(reflectedWeight, frame.radiance.rgb);
        else pushRay(slot, state.pending, c.reflected);  // with the parent's media, still current
    }
    // The refracted ray's medium stack replaces the parent's (kept when the
    // reflected ray goes on with it).
    uint parentMedia[MAX_MEDIA];
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k) parentMedia[k] = media[k];
    c.refracted.mediaCount = crossSurface(h, r.mediaCount, c.removeAt);
    if (refracts && !refractedWaits) {
        r = c.refracted;  // traced next, with its medium stack
        return true;
    }
    if (!refracts) deferRay(slot, state, c.refracted);
    else if (stackFull) state.lost.rgb += weighted(transmittedWeight, frame.radiance.rgb);
    else pushRay(slot, state.pending, c.refracted);
    // The reflected ray goes on (if it is traced at all), with the parent's media.
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k) media[k] = parentMedia[k];
    r = c.reflected;
    return reflects;
}

#endif
