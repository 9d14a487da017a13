// What a dispatch fixes for all its invocations, set once at the start of
// main (beginDispatch): the tile, how pixels are shared out, the trace
// settings. (The per-pixel values live in main's locals and are passed down:
// Mesa 22.3's llvmpipe keeps memory for every dispatch of a shader with such
// private globals, tests/soak_test.sh.)
#ifndef SNELL_SCHEDULE_DISPATCH_GLSL
#define SNELL_SCHEDULE_DISPATCH_GLSL

layout(constant_id = SNELL_SPEC_AMPLIFYING) const bool AMPLIFYING = false;
// Each sample's light kept apart until its first step ends, so that the host
// may re-trace only the samples whose light hangs on an undecided decision
// (steps.glsl, closeSample): with margins, 2 to 64 samples, and light that
// cannot grow (saturation would tie a pixel's samples together).
layout(constant_id = SNELL_SPEC_BY_SAMPLE) const bool BY_SAMPLE = false;
// Some material traps light, where it grows without end (ks.w of a material;
// render/Truncation.h, growthTraps): a pixel whose trees meet one may go on
// below the floor, so rays under the floor wait rather than being lost.
layout(constant_id = SNELL_SPEC_TRAPS) const bool TRAPS = false;

layout(set = 0, binding = SNELL_BINDING_SLOT_STATES, std430) buffer SlotStateBlock { SlotState slotStates[]; };
layout(push_constant) uniform TileBlock { TileParams tile; };

uint invocations;  // of this dispatch
// This workgroup's share of the tile's pixels (takePixel). lavapipe runs
// each thread's workgroups from one contiguous range of IDs, so with share =
// ID the threads took the tile's column stripes side by side: a 1024-wide
// tile with its glass on the left ran on one thread. A stride coprime with
// the count near count / golden ratio spreads each range over the tile.
uint share;
uint helpedShare;  // the share the invocation takes its pixels from (takePixel)
uint tilePixels;     // the tile's pixels
float tolerance;     // on each pixel's truncation bound; 0: a fixed tree
float floorCutOff;   // the lowest cut-off (the fixed tree's cut-off without a tolerance)
float firstCutOff;   // a pixel's first step's
uint samples;        // sub-pixel samples a pixel traces
uint pixelBudget;    // rays a pixel's trees may trace; 0: no limit
float saturation;    // a channel's sum where it is final (amplifying scenes)

// The dispatch's constants (above) from the frame and the tile, its counts
// zeroed, and the spheres of a small scene preloaded.
void beginDispatch() {
    invocations = gl_NumWorkGroups.x * uint(SNELL_WORKGROUP_SIZE);
    share = gl_WorkGroupID.x * max(tile.workgroupStride, 1u) % gl_NumWorkGroups.x;
    helpedShare = share;
    tilePixels = tile.width * tile.height;
    [[unroll]] for (int k = 0; k < SNELL_RAY_COUNTER_COUNT; ++k) countedRays[k] = 0u;
    preloadSpheres();
    // Mesa 22.3's lavapipe specialises a shader on values it reads from
    // uniforms with constant offsets where it judges that worthwhile
    // (lvp_inline_uniforms); for this kernel it judged so because of the
    // tolerance, and then compiled a new copy of the kernel at every dispatch
    // and kept each one (an LLVM compile and ~0.75 MB a dispatch). A zero it
    // cannot see as uniform (dispatches are one row of workgroups) keeps the
    // tolerance out of that analysis; tests/soak_test.sh watches for it.
    uint opaqueZero = gl_NumWorkGroups.y - 1u;
    tolerance = frame.tolerance + float(opaqueZero);
    floorCutOff = frame.minWeight;
    // Under a tolerance each pixel starts on the ladder's first rung, 1/4,
    // whatever the tolerance (render/RenderRequest.h, kFirstRung).
    firstCutOff = tolerance > 0.0 ? max(floorCutOff, 0.25) : floorCutOff;
    samples = frame.sampleCount;
    pixelBudget = frame.treeBudget * samples;
    // SPEC §4 amplifying materials: a channel whose pixel sum has reached 1
    // (times the samples, as the sum is of samples) is final in 8 bits.
    saturation = AMPLIFYING ? float(samples) : 3.0e38;
}

#endif
