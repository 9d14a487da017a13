// A pixel's steps (render/Truncation.h; CpuRenderer::renderPixel is the
// twin): its trees at a cut-off, what each step proves of its exact colour,
// the next rung of the cut-off ladder, and the finished pixel written out.
#ifndef SNELL_SCHEDULE_STEPS_GLSL
#define SNELL_SCHEDULE_STEPS_GLSL

// What the shader writes: the tile's pixels, row-major (a buffer: on lavapipe
// an imageStore in a loop costs 13x a buffer store; rgb the colour, a the
// pixel's truncation bound), and its own bookkeeping.
layout(set = 0, binding = SNELL_BINDING_OUTPUT, std430) writeonly buffer OutputBlock { OutputPixel outputPixels[]; };

SlotState freshPixel(uint pixelIndex) {
    return SlotState(vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0), vec4(INFINITY), vec4(0.0), vec4(0.0), pixelIndex, 0u, 0u, 0u,
                     0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u, firstCutOff, 0.0, INFINITY, INFINITY, 0.0, 0u, 0.0, 0.0,
                     vec4(0.0), vec4(0.0), 0u, 0u, 0u, 0.0, vec4(0.0));
}

// Where a pixel's flagged samples go (BY_SAMPLE): beside its OutputPixel, at
// the tile's pixel index. (A macro: SPIRV-Tools' dead-code pass of Debian 12
// fails on a call that returns a buffer reference.)
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer FlaggedSampleBlock { FlaggedSamples pixels[]; };
#define flaggedSamples() FlaggedSampleBlock(uvec2(frame.flaggedAddressLow, frame.flaggedAddressHigh))

// The first step's tree of the pixel's latest sample is finished (BY_SAMPLE):
// where its light hangs on an undecided decision, or its shading's rounding
// is more than the host lets a pixel keep without a re-trace (TileReadback.cpp,
// retraceAbove), the sample is flagged and its light kept apart; else its
// shading's rounding joins the others'.
void closeSample(inout SlotState state) {
    uint k = state.started - 1u;
    float limit = tolerance > 0.0 ? min(0.5 / 255.0, tolerance) : 0.5 / 255.0;
    if (state.sampleFlagged != 0u || state.sampleLight.a > limit) {
        state.flagged.rgb += state.sampleLight.rgb;
        if (k < 32u) state.flaggedLow |= 1u << k;
        else state.flaggedHigh |= 1u << (k - 32u);
    } else {
        state.flagged.a += state.sampleLight.a;
    }
    state.sampleLight = vec4(0.0);
    state.sampleFlagged = 0u;
}

// What a step of a pixel proves of its exact colour: its colour is a lower
// bound and its colour plus the most light of the rays it has not traced
// (each one's weight times its reach, rayReach) an upper bound; the pixel keeps the best of each (render/Truncation.h,
// PixelEstimate, its twin). Returns the bound on the clamped colour.
float addStep(inout SlotState state, float samples, out bool unbounded) {
    vec3 value = state.sum.rgb / samples;
    state.lower.rgb = max(state.lower.rgb, value);
    state.upper.rgb = min(state.upper.rgb, value + (state.lost.rgb + state.deferredLight.rgb) / samples);
    vec3 gap = min(state.upper.rgb, vec3(1.0)) - min(state.lower.rgb, vec3(1.0));
    unbounded = any(bvec3(uvec3(greaterThan(state.upper.rgb, vec3(3.0e38))) & uvec3(lessThan(state.lower.rgb, vec3(1.0)))));
    return max(0.0, max(gap.r, max(gap.g, gap.b)));
}

// The estimated error of a pixel that cannot be certified, from how far its
// last steps moved its colour and how the light its untraced weight may carry
// changed: a geometric tail (render/Truncation.h, ErrorEstimate, its twin).
// +inf while unknown or not shrinking.
float estimateError(inout SlotState state, float samples) {
    vec3 colour = min(state.lower.rgb, vec3(1.0));
    vec3 open = mix(weighted(state.deferred.rgb, frame.localRadiance.rgb) / samples, vec3(0.0),
                    greaterThanEqual(colour, vec3(1.0)));
    float weight = max(open.r, max(open.g, open.b));
    if (state.steps > 0u) {
        vec3 moved = abs(colour - state.settled.rgb);
        state.moveBefore = state.lastMove;
        state.lastMove = max(moved.r, max(moved.g, moved.b));
    }
    float previousWeight = state.steps > 0u ? state.settledWeight : INFINITY;
    state.settled = vec4(colour, 0.0);
    state.settledWeight = weight;
    state.steps++;
    if (state.steps < 3u || !(weight < previousWeight)) return INFINITY;
    float change = state.lastMove;
    float rho = max(change / state.moveBefore, weight / previousWeight);
    if (!(rho < 1.0) && change > 0.0) return INFINITY;
    return max(weight, change > 0.0 ? change / (1.0 - rho) : 0.0);
}

// The rung of the cut-off ladder at or below w > 0: w with its mantissa
// cleared, a power of two (render/RenderRequest.h, cutOffRung).
float cutOffRung(float w) { return uintBitsToFloat(floatBitsToUint(w) & 0x7f800000u); }

// What a finished step proves of its pixel (addStep, estimateError).
struct StepOutcome {
    float bound;     // on the clamped colour's truncation error
    bool unbounded;  // no finite bound: light of a gain >= 1 was left
    float estimate;  // the estimated error where unbounded
    bool certified;  // bound within the tolerance
    bool settled;    // stopped on its estimate instead
};

StepOutcome assessStep(inout SlotState state) {
    StepOutcome o;
    // (SPEC §3 mean, clamped on output.)
    o.bound = addStep(state, float(samples), o.unbounded);
    o.estimate = estimateError(state, float(samples));
    o.certified = o.bound <= tolerance;
    o.settled = frame.estimate != 0u && o.unbounded && o.estimate <= tolerance &&
                (state.amplified == 0u || o.estimate <= frame.amplifiedEstimate);
    return o;
}

// The cut-off of the pixel's next step, or 0 where it is finished. The next
// rung: four below the heaviest ray this step left (render/RenderRequest.h,
// nextRung), not under the floor; but a pixel whose trees gained weight goes
// on below it, until its diverging channels saturate or its trees reach the
// budget (SPEC §4 amplifying materials; as CpuRenderer::renderPixel does).
float nextCutOff(SlotState state, StepOutcome o) {
    float heaviest = state.heaviestLeft;
    if (!(tolerance > 0.0) || o.certified || o.settled || !(heaviest > 0.0) || state.overBudget != 0u) return 0.0;
    bool belowFloor = TRAPS && o.unbounded && state.amplified != 0u && pixelBudget != 0u;
    float next = cutOffRung(heaviest) / 16.0;
    if (!belowFloor) next = max(floorCutOff, next);
    return next <= heaviest ? next : 0.0;
}

// The next step traces on from the rays this one left in the frontier.
void beginStep(inout SlotState state) {
    state.deferred.rgb = vec3(0.0);
    state.deferredLight.rgb = vec3(0.0);
    state.heaviestLeft = 0.0;
    state.frontierOld = state.frontierCount;
}

// What a pixel's undecided decisions and shading's rounding may have done to
// its colour, a sample's mean, for its host (host/gpu/TileReadback.cpp: a
// re-trace, a wider bound, or neither where the pixel is white either way):
// `moved`, how far either way (its undecided rays' light, where finite in
// every channel, else the most light one hit of them returns; its undecided
// shadow rays' light; shading's rounding), and
// `excess`, the light its sum holds that the exact one may not. Returns its
// flags. Rounded up by 2^-20 of themselves: a few float operations' rounding.
uint undecidedReport(SlotState state, out float excess, out float moved) {
    const float up = (1.0 + 1.0 / 1048576.0) / float(samples);
    vec3 light = state.undecided.rgb;
    bool unbounded = any(isinf(light));
    float widening = maxChannel(mix(light, vec3(0.0), isinf(light)));
    if (unbounded) widening = max(widening, state.undecidedLocal);
    moved = (widening + state.undecided.a + state.shading) * up;
    excess = (state.unsureLight + state.shading) * up;
    bool undecided = maxChannel(light) > 0.0 || state.undecidedLocal > 0.0 || state.undecided.a > 0.0;
    return (undecided ? SNELL_PIXEL_UNDECIDED : 0u) | (undecided && unbounded ? SNELL_PIXEL_MOVED_UNBOUNDED : 0u);
}

// The finished pixel written out (render/Truncation.h: its colour, bound and
// how it stopped), and the invocation moved on to its next pixel.
void finishPixel(uint slot, inout SlotState state, StepOutcome o, uint shadowRays) {
    // A pixel that dropped light that may grow, and has not saturated, has
    // neither a bound nor an estimate: it is over the tolerance, and says why.
    bool dropped = state.droppedGrowing != 0u && o.unbounded;
    // A bounded pixel the floor stopped over the tolerance states its
    // estimate, where that is within it, beside its bound.
    o.settled = o.settled || (frame.estimate != 0u && !o.certified && !o.unbounded && o.estimate <= tolerance &&
                              (state.amplified == 0u || o.estimate <= frame.amplifiedEstimate));
    bool overTolerance = tolerance > 0.0 && !o.certified && (!o.settled || dropped);
    uint flags = (state.overBudget != 0u ? SNELL_PIXEL_OVER_BUDGET : 0u) |
                 (overTolerance ? SNELL_PIXEL_OVER_TOLERANCE : 0u) | (dropped ? SNELL_PIXEL_DROPPED_GROWING : 0u);
    float excess = 0.0, moved = 0.0;
    if (DECISIONS) flags |= undecidedReport(state, excess, moved);
    outputPixels[state.pixel] = OutputPixel(vec4(state.lower.rgb, o.unbounded ? -o.bound : o.bound),
                                            o.settled && !dropped ? o.estimate : -1.0,
                                            min(state.treeRays, SNELL_PIXEL_RAYS_LIMIT) << SNELL_PIXEL_RAYS_SHIFT | flags,
                                            excess, moved);
    // Its flagged samples hold all its undecided light where each sample's
    // light was kept apart to the end: where it ended after one step.
    if (BY_SAMPLE) {
        bool bySample = state.steps == 1u;
        flaggedSamples().pixels[state.pixel] = FlaggedSamples(state.flagged, bySample ? state.flaggedLow : 0u,
                                                              bySample ? state.flaggedHigh : 0u, 0u, 0u);
    }
    uint finished = state.finished + 1u;
    uint rays = state.rays;
    state = freshPixel(takePixel());
    state.finished = finished;
    state.rays = rays;
    slotStates[slot].finished = finished;
    slotStates[slot].rays = rays + shadowRays;
}

// The pixel's step has no ray left: on at a lower cut-off (cutOff), or the
// pixel is finished and the invocation moves to its next one (pixel, within
// the tile). Returns whether the invocation is done with the tile.
bool endStep(uint slot, inout SlotState state, inout uvec2 pixel, inout float cutOff, uint shadowRays) {
    if (BY_SAMPLE && state.steps == 0u) closeSample(state);  // its last sample's first step
    StepOutcome outcome = assessStep(state);
    float next = nextCutOff(state, outcome);
    if (next > 0.0) {
        cutOff = next;
        beginStep(state);
        return false;
    }
    finishPixel(slot, state, outcome, shadowRays);
    pixel = uvec2(state.pixel % tile.width, state.pixel / tile.width);
    cutOff = firstCutOff;
    return state.pixel >= tilePixels;
}

#endif
