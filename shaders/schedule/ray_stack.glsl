// Where an invocation's rays wait: its stack of children (pushRay,
// popRay) and its frontier of rays left under a cut-off, in device memory
// so that an invocation can suspend between dispatches. Each pending ray
// carries its weight, depth, the sphere it starts on, whether it heads into
// that sphere, and its medium stack (innermost last).
#ifndef SNELL_SCHEDULE_RAY_STACK_GLSL
#define SNELL_SCHEDULE_RAY_STACK_GLSL

layout(constant_id = SNELL_SPEC_RAY_STACK) const uint RAY_STACK = 1u;
// Entries of an invocation's frontier: the rays a step leaves under its
// cut-off, which the next step traces on (0: a fixed tree, nothing deferred).
layout(constant_id = SNELL_SPEC_FRONTIER) const uint FRONTIER = 0u;

layout(set = 0, binding = SNELL_BINDING_RAY_STACK, std430) buffer RayStackBlock { PendingRay rayStack[]; };
layout(set = 0, binding = SNELL_BINDING_MEDIA_STACK, std430) buffer MediaStackBlock { uint mediaStack[]; };
// The ray and media stacks again, through their device addresses (a pending
// ray as four words of two halves).
layout(buffer_reference, std430, buffer_reference_align = 16) buffer PendingRays { u64vec2 words[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer MediaEntries { uint spheres[]; };
#ifdef SNELL_FP64
layout(set = 0, binding = SNELL_BINDING_RAY_STACK_LOW, std430) buffer RayStackLowBlock { PendingRay rayStackLow[]; };
#endif

// An invocation's entries in the ray and media buffers: its stack of
// RAY_STACK entries, then its frontier of FRONTIER, entry k of every
// invocation side by side (k · invocations + slot). Side by side, the lanes of
// a subgroup touch neighbouring memory (coalesced on a GPU), and a render
// whose rays wait in few entries touches few pages: laid out an invocation
// after another, each invocation's first frontier entry was a page of its own,
// and on lavapipe faulting those pages in cost 1–2 ms a render.
uint stackEntry(uint slot, uint k) { return k * invocations + slot; }
uint frontierEntry(uint slot, uint k) { return (RAY_STACK + k % max(FRONTIER, 1u)) * invocations + slot; }

// The stacks' entries, through whichever the driver reads and writes faster
// at per-lane indices: Mesa 25's lavapipe checks each lane's offset into a
// storage buffer against its size, where through an address a load is one
// masked gather a component, and the stack's traffic measured 1.05–1.25×
// faster; Mesa 22.3 goes lane by lane there (docs/log/kernel-profiled.md, "The ray
// stack through its address"). Without the buffer's checks an entry past the
// end would not be dropped: followChildren keeps within RAY_STACK (stackFull).
layout(constant_id = SNELL_SPEC_STACKS_BY_ADDRESS) const bool STACKS_BY_ADDRESS = false;
// (Macros, not functions: SPIRV-Tools' dead-code pass of Debian 12 fails on
// a call that returns a buffer reference.)
#define pendingRays() PendingRays(uvec2(frame.rayStackAddressLow, frame.rayStackAddressHigh))
#define mediaEntries() MediaEntries(uvec2(frame.mediaStackAddressLow, frame.mediaStackAddressHigh))
void storePending(uint entry, PendingRay p) {
    if (STACKS_BY_ADDRESS) {
        uint w = 4u * entry;
        pendingRays().words[w] = toHalves(floatBitsToUint(p.origin));
        pendingRays().words[w + 1u] = toHalves(floatBitsToUint(p.direction));
        pendingRays().words[w + 2u] = toHalves(floatBitsToUint(p.weight));
        pendingRays().words[w + 3u] = toHalves(uvec4(p.depth, p.fromSphere, p.flags, p.resumeShading));
    } else {
        rayStack[entry] = p;
    }
}
PendingRay loadPending(uint entry) {
    if (STACKS_BY_ADDRESS) {
        uint w = 4u * entry;
        uvec4 last = fromHalves(pendingRays().words[w + 3u]);
        return PendingRay(uintBitsToFloat(fromHalves(pendingRays().words[w])),
                          uintBitsToFloat(fromHalves(pendingRays().words[w + 1u])),
                          uintBitsToFloat(fromHalves(pendingRays().words[w + 2u])), last.x, last.y, last.z, last.w);
    }
    return rayStack[entry];
}
void storeMedium(uint i, uint sphere) {
    if (STACKS_BY_ADDRESS) mediaEntries().spheres[i] = sphere;
    else mediaStack[i] = sphere;
}
uint loadMedium(uint i) {
    if (STACKS_BY_ADDRESS) return mediaEntries().spheres[i];
    return mediaStack[i];
}

const uint COVERED = 0x80000000u;  // PendingRay.flags: Ray.covered

void storeRay(uint entry, Ray r) {
#ifdef SNELL_FP64
    // The low entry holds the two lower parts of each double: origin and
    // direction the middle ones, weight.xyz and the w's the last ones.
    vec3 origin, originMid, originLow, dir, dirMid, dirLow;
    splitDoubleExact(r.origin, origin, originMid, originLow);
    splitDoubleExact(r.dir, dir, dirMid, dirLow);
    rayStackLow[entry].origin = vec4(originMid, dirLow.x);
    rayStackLow[entry].direction = vec4(dirMid, dirLow.y);
    rayStackLow[entry].weight = vec4(originLow, dirLow.z);
#else
    vec3 origin = r.origin, dir = r.dir;
#endif
    storePending(entry, PendingRay(vec4(origin, float(r.off.x)), vec4(dir, float(r.off.y)), vec4(r.weight, 0.0), r.depth,
                                   r.fromSphere, (r.inward ? 1u : 0u) | (r.mediaCount << 1) | (r.covered ? COVERED : 0u),
                                   r.resumeShading));
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k)
        if (uint(k) < r.mediaCount) storeMedium(entry * uint(MAX_MEDIA) + uint(k), media[k]);
}

Ray loadRay(uint entry) {
    PendingRay p = loadPending(entry);
    uint mediaCount = (p.flags & ~COVERED) >> 1;
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k)
        if (uint(k) < mediaCount) media[k] = loadMedium(entry * uint(MAX_MEDIA) + uint(k));
#ifdef SNELL_FP64
    PendingRay low = rayStackLow[entry];
    precise dvec3 origin = (dvec3(p.origin.xyz) + dvec3(low.origin.xyz)) + dvec3(low.weight.xyz);
    precise dvec3 dir = (dvec3(p.direction.xyz) + dvec3(low.direction.xyz)) + dvec3(low.origin.w, low.direction.w, low.weight.w);
#else
    vec3 origin = p.origin.xyz, dir = p.direction.xyz;
#endif
    return Ray(origin, dir, p.weight.rgb, p.depth, p.fromSphere, (p.flags & 1u) != 0u, mediaCount, p.resumeShading,
               rvec2(p.origin.w, p.direction.w), (p.flags & COVERED) != 0u);
}

void pushRay(uint slot, inout uint pending, Ray r) {
    storeRay(stackEntry(slot, pending), r);
    pending++;
}

Ray popRay(uint slot, inout uint pending) {
    pending--;
    return loadRay(stackEntry(slot, pending));
}

#endif
