// snell's renderer: SPEC §3–§5 in float32, or in double when compiled with
// SNELL_FP64 (precision.glsl; --precision fp64). main below is the path of
// one ray; its steps are pure functions in physics/, one concept a file:
//
//   camera.glsl    cameraRay       SPEC §3: the ray through a sub-pixel
//   margins.glsl   offAt, ...      the margins of the decisions rounding can flip
//   hit.glsl       findHit         SPEC §4.1: the closest hit, brute force,
//                  occluded          BVH walk (bvh_walk.glsl) or ray query
//   shade.glsl     ambientTerm,    SPEC §4.3: the local Phong term, binary
//                  shadeLight        shadows
//   children.glsl  children        SPEC §4.4–4.5: reflected and refracted rays
//   media.glsl     relativeIndex,  SPEC §4.5: the medium stack
//                  crossSurface
//
// Which ray comes next, where rays wait and which are lost is scheduling, in
// schedule/: pixels dealt to persistent invocations (pixels.glsl), the ray
// stack and the frontier (ray_stack.glsl, frontier.glsl), a pixel's steps
// down the cut-off ladder (steps.glsl), the tree (tree.glsl), the lights'
// loop and shared shadow rays (lights.glsl), and the loop budget and
// counters (loop_budget.glsl, counters.glsl). The double-precision twin of
// the physics is host/reference/CpuRenderer.cpp (docs/design.md maps each
// function to its twin).
//
// Invocations are persistent: invocation k of K starts on pixel k of the tile
// and then takes the next pixel its workgroup has not taken (takePixel), one ray
// at a time, as soon as its last one is finished. So a SIMD row stays full
// while its pixels' ray trees differ in size, and an invocation's ray stack
// (device memory) is reused from pixel to pixel instead of being one per pixel.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#ifdef SNELL_RAY_QUERY
#extension GL_EXT_ray_query : require
#endif
#include "shared_layout.h"
#include "intersect.glsl"
#include "wide_words.glsl"

layout(local_size_x = SNELL_WORKGROUP_SIZE) in;

// Physics: pure functions of the scene.
#include "physics/scene.glsl"
#include "physics/ray.glsl"
#include "physics/camera.glsl"
#include "physics/hit.glsl"
#include "physics/shade.glsl"
#include "physics/media.glsl"
#include "physics/children.glsl"

// Scheduling.
#include "schedule/counters.glsl"
#include "schedule/dispatch.glsl"
#include "schedule/ray_stack.glsl"
#include "schedule/frontier.glsl"
#include "schedule/pixels.glsl"
#include "schedule/steps.glsl"
#include "schedule/tree.glsl"
#include "schedule/lights.glsl"

// Whether the invocation leaves the pixel loop: with a loop budget every
// lane stays in it until the subgroup leaves together (so the subgroup
// operations in it see all lanes), suspending where the budget is spent.
bool leavesLoop(bool done, inout bool suspended) {
    if (LOOP_BUDGET == 0u) return done;
    if (subgroupAll(done)) return true;
    suspended = loopBudgetSpent();
    return suspended;
}

// Asked to stop (Ctrl-C, SIGTERM) while the dispatch runs: read every 256
// passes, so even a pixel whose tree never ends is left promptly.
bool cancelled(inout uint passes) {
    return (++passes & 255u) == 0u && atomicAdd(counters[SNELL_COUNTER_CANCEL], 0u) != 0u;
}

void main() {
    uint slot = gl_GlobalInvocationID.x;
    beginDispatch();

    // This invocation's progress: its current pixel, that pixel's sum, and the
    // rays on its stack and in its frontier. Fresh, or resumed from the last
    // dispatch.
    SlotState state;
    if (tile.resume != 0u) state = slotStates[slot];
    else state = freshPixel(takePixel());
    float cutOff = state.cutOff;
    uint shadowRays = 0u;               // cast in this dispatch (for SlotState.rays)
    uint deepest = 0u;
    bool done = state.pixel >= tilePixels;
    uvec2 pixel = uvec2(state.pixel % tile.width, state.pixel / tile.width);  // within the tile

    Ray ray;
    bool hasRay = false;
    bool suspended = false;
    uint passes = 0u;
    while (!leavesLoop(done, suspended)) {
        // This pass, and ahead the pass that ends each loop the pass reaches
        // (loop_budget.glsl): the closest-hit walk, the lights' loop and the
        // occlusion walk in it, takePixel's three (endStep).
        tick(2u + (HAS_LIGHTS ? 2u : 0u) + (HELPS ? 3u : 0u));
        // Cancelled: this invocation drops its work and the host discards the tile.
        if (!done && cancelled(passes)) {
            done = true;
            hasRay = false;
            state.pending = 0u;
            state.pixel = tilePixels;
        }
        // A step of the pixel is finished when it has no ray left: what it
        // proves, and whether a lower cut-off is worth it (then the step goes
        // on from the frontier in this very pass), else the pixel is done.
        if (!done && !hasRay && state.pending == 0u && state.frontierOld == 0u && state.started == samples)
            done = endStep(slot, state, pixel, cutOff, shadowRays);
        // The ray: a child waiting on the stack, a ray left in the frontier, or a camera ray.
        if (!done && !hasRay) hasRay = nextRay(slot, state, pixel, ray);
        if (COUNT_LANES) countLanes(hasRay, traceSlots, traceBusy);

        // 1–2. Its closest hit, unless it waits for a lower cut-off or is lost;
        // the background on a miss, the ambient part of the local term on a
        // hit (once: not when its shading resumes).
        vec3 weight = vec3(0.0);
        Hit h;
        bool shading = false;
        if (hasRay && admitRay(slot, state, ray, cutOff, weight)) {
            shading = findHit(ray, h);
            // Where rounding may have chosen the hit, the ray's light may be
            // either answer's: at most its weight times its reach (margins.glsl).
            if (DECISIONS && h.undecided && !ray.covered && ray.resumeShading == 0u) {
                addUndecided(state, vec4(weighted(weight, rayReach(ray)), 0.0), weight);
                ray.covered = true;
            }
            if (!shading) addLight(state, ray, weighted(weight, frame.background.rgb), false);
            else if (ray.resumeShading == 0u) addLight(state, ray, weighted(weight, ambientTerm(h)), false);
            deepest = max(deepest, ray.depth);
        }
        hasRay = shading;
        // 3. The lights' part of the local term (suspended part-way where the
        // loop budget is spent).
        if (shadeLights(state, ray, weight, h, shading, shadowRays)) {
            suspended = true;
            break;
        }
        // 4–5. Its children: one is traced next, the others wait or are lost.
        if (shading) hasRay = followChildren(slot, state, ray, weight, h, cutOff);
    }

    if (suspended) {
        // The ray in hand waits on the stack for the next dispatch.
        if (hasRay) pushRay(slot, state.pending, ray);
        if (!done) atomicAdd(counters[SNELL_COUNTER_UNFINISHED], 1u);
    }
    // Under a loop budget the next dispatch resumes every invocation, those
    // whose subgroup finished included: each leaves its state, done or not.
    state.cutOff = cutOff;
    state.rays += shadowRays;
    if (LOOP_BUDGET != 0u) slotStates[slot] = state;
    addCounters(deepest);
    reportLoopLimit();
}
