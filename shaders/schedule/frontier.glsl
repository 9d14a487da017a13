// Which rays a step of a pixel traces and which wait for a lower cut-off:
// the frontier (render/Truncation.h; its CPU twin is CpuRenderer's
// TreeTrace::defer).
#ifndef SNELL_SCHEDULE_FRONTIER_GLSL
#define SNELL_SCHEDULE_FRONTIER_GLSL

// Whether a ray of weight w is traced under cutOff: that of the pixel in
// hand, the minimum weight or, under a tolerance, the one its current step
// uses (SlotState.cutOff).
bool worthTracing(vec3 w, float cutOff) {
    float m = max(w.x, max(w.y, w.z));
    return m > 0.0 && m >= cutOff;
}

// Each ray's light bounded by where it starts (render/Reach.h), not by R alone.
layout(constant_id = SNELL_SPEC_REACH) const bool REACH = false;
layout(set = 0, binding = SNELL_BINDING_REACH) uniform utextureBuffer reachTexels;

// The most light a ray that starts on `sphere` can bring per unit weight,
// into it or out of it (CpuRenderer's TreeTrace::sphereReach).
vec3 sphereReach(uint sphere, bool inward) {
    if (!REACH || (inward && frame.reachInward == 0u)) return frame.radiance.rgb;
    return texel(reachTexels, 2u * sphere + (inward ? 1u : 0u)).rgb;  // SphereReach
}
// The same for ray r, or R for a camera ray and one whose light may be
// either outcome's of an undecided decision (TreeTrace::reachOf).
vec3 rayReach(Ray r) {
    return r.covered || r.fromSphere == NONE ? frame.radiance.rgb : sphereReach(r.fromSphere, r.inward);
}

// A ray under the cut-off (its medium stack in `media`) waits in the frontier
// for the pixel's next step; one under the floor is lost for good, but in a
// scene with traps, where a pixel may need to go below it (nextCutOff), it
// waits. (Only there: elsewhere storing rays that no step traces cost more
// than tracing the rest.)
void deferRay(uint slot, inout SlotState state, Ray r) {
    float m = max(r.weight.r, max(r.weight.g, r.weight.b));
    if (!(m > 0.0)) return;
    bool mayGoBelowFloor = TRAPS && frame.treeBudget != 0u;
    vec3 light = weighted(r.weight, rayReach(r));  // the most it can bring
    if (FRONTIER > 0u && state.frontierCount < FRONTIER && (mayGoBelowFloor || m >= frame.minWeight)) {
        storeRay(frontierEntry(slot, state.frontierHead + state.frontierCount), r);
        state.frontierCount++;
        state.deferred.rgb += r.weight;
        state.deferredLight.rgb += light;
        state.heaviestLeft = max(state.heaviestLeft, m);
    } else {
        // Light that may grow, lost for want of room (the CPU reference keeps
        // it): no estimate of the pixel's error holds.
        if (mayGoBelowFloor && FRONTIER > 0u) state.droppedGrowing = 1u;
        state.lost.rgb += light;
    }
}

// The cut-off that decides whether a ray is traced now: the step's, while the
// frontier has room for what it leaves; the floor once it is full (the ray is
// traced now rather than lost: the tree only grows, and no step traces any
// ray twice).
float tracingCutOff(SlotState state, float cutOff) {
    return FRONTIER > 0u && state.frontierCount >= FRONTIER ? frame.minWeight : cutOff;
}

#endif
