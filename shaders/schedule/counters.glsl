// What the kernel tells the host besides the image: the dispatch's counters
// (shared_layout.h: SNELL_COUNTER_*), the loop budget that keeps lavapipe's
// loop limit (loop_budget.glsl), and, when measuring, rays and busy lanes.
#ifndef SNELL_SCHEDULE_COUNTERS_GLSL
#define SNELL_SCHEDULE_COUNTERS_GLSL

// coherent: the shares' bits are read while other invocations clear them.
layout(set = 0, binding = SNELL_BINDING_COUNTERS, std430) coherent buffer CounterBlock { uint counters[]; };
#include "loop_budget.glsl"  // (it reports through the counters)

layout(constant_id = SNELL_SPEC_COUNT_RAYS) const bool COUNT_RAYS = false;
// Measuring the kernel: how many of a subgroup's lanes do useful work in each
// pass of the trace loop and of the BVH walk (lanes that left a loop, or
// have nothing to trace, idle while the others go on).
layout(constant_id = SNELL_SPEC_COUNT_LANES) const bool COUNT_LANES = false;
uint traceSlots = 0u, traceBusy = 0u, walkSlots = 0u, walkBusy = 0u;  // this invocation's share

// Counts a pass of the subgroup's active lanes: subgroup-size slots, `busy` of them used.
void countLanes(bool busy, inout uint slots, inout uint used) {
    uint n = subgroupAdd(busy ? 1u : 0u);
    if (subgroupElect()) {
        slots += gl_SubgroupSize;
        used += n;
    }
}

uint countedRays[SNELL_RAY_COUNTER_COUNT];

// The physics' search loops report each pass (physics/hit.glsl).
void sphereLoopPass() { tick(1u); }
void walkLoopPass() {
    tick(1u);
    if (COUNT_LANES) countLanes(true, walkSlots, walkBusy);
}

// This invocation's counts into the dispatch's counters (read by the host).
void addCounters(uint deepest) {
    if (deepest > 0u) atomicMax(counters[SNELL_COUNTER_DEEPEST], deepest);
    if (COUNT_RAYS) {
        [[unroll]] for (int k = 0; k < SNELL_RAY_COUNTER_COUNT; ++k)
            if (countedRays[k] != 0u) atomicAdd(counters[k], countedRays[k]);
    }
    if (COUNT_LANES) {
        if (traceSlots != 0u) atomicAdd(counters[SNELL_COUNTER_TRACE_SLOTS], traceSlots);
        if (traceBusy != 0u) atomicAdd(counters[SNELL_COUNTER_TRACE_BUSY], traceBusy);
        if (walkSlots != 0u) atomicAdd(counters[SNELL_COUNTER_WALK_SLOTS], walkSlots);
        if (walkBusy != 0u) atomicAdd(counters[SNELL_COUNTER_WALK_BUSY], walkBusy);
    }
}

#endif
