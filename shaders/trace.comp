// snell's renderer: SPEC §3–§5 in float32, or in double when compiled with
// SNELL_FP64 (precision.glsl; --precision fp64).
// The path of one ray: camera (cameraRay) -> closestHit / intersectSphere ->
// shade (local Phong term, shadow rays) -> children pushed on the explicit
// stack (spawnChildren). Its double-precision twin is
// host/reference/CpuRenderer.cpp; the intersection maths is explained in
// host/reference/Intersect.h.
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

// What this scene uses (host/gpu/ComputeRenderer.cpp sets them): code for a
// feature the scene lacks is dead and removed when the pipeline is compiled.
layout(constant_id = SNELL_SPEC_USE_BVH) const bool USE_BVH = false;
// Without a BVH and at most SNELL_MAX_UNROLLED_SPHERES spheres: their number,
// so the loops over them unroll and read each sphere at a constant offset (on
// lavapipe ~3x faster than a counted loop); else 0.
layout(constant_id = SNELL_SPEC_SPHERE_COUNT) const uint SPHERE_COUNT = 1u;
// With SPHERE_COUNT: bit i set when sphere i is an ellipsoid, so each unrolled
// test holds the code of its own kind only.
layout(constant_id = SNELL_SPEC_ELLIPSOID_MASK) const uint ELLIPSOID_MASK = 0u;
// Every sphere is in the uniform block (SNELL_BLOCK_SPHERES at most).
layout(constant_id = SNELL_SPEC_SPHERES_IN_BLOCK) const bool SPHERES_IN_BLOCK = false;
// With a BVH: the entries of the walk's stack (GpuScene::bvhStackSize).
layout(constant_id = SNELL_SPEC_BVH_DEPTH) const uint BVH_DEPTH = 1u;
layout(constant_id = SNELL_SPEC_HAS_ELLIPSOIDS) const bool HAS_ELLIPSOIDS = true;
layout(constant_id = SNELL_SPEC_HAS_REFRACTION) const bool HAS_REFRACTION = true;
layout(constant_id = SNELL_SPEC_HAS_REFLECTION) const bool HAS_REFLECTION = true;
layout(constant_id = SNELL_SPEC_HAS_LIGHTS) const bool HAS_LIGHTS = true;
layout(constant_id = SNELL_SPEC_COUNT_RAYS) const bool COUNT_RAYS = false;
// Measuring the kernel: how many of a subgroup's lanes do useful work in each
// pass of the trace loop and of the BVH walk (lanes that left a loop, or
// have nothing to trace, idle while the others go on).
layout(constant_id = SNELL_SPEC_COUNT_LANES) const bool COUNT_LANES = false;
layout(constant_id = SNELL_SPEC_BVH_WORDS) const bool BVH_WORDS = false;
layout(constant_id = SNELL_SPEC_STACK_IN_REGISTERS) const bool STACK_IN_REGISTERS = false;
layout(constant_id = SNELL_SPEC_SHARE_SHADOW_RAYS) const bool SHARE_SHADOW_RAYS = false;
uint traceSlots = 0u, traceBusy = 0u, walkSlots = 0u, walkBusy = 0u;  // this invocation's share

// Counts a pass of the subgroup's active lanes: subgroup-size slots, `busy` of them used.
void countLanes(bool busy, inout uint slots, inout uint used) {
    uint n = subgroupAdd(busy ? 1u : 0u);
    if (subgroupElect()) {
        slots += gl_SubgroupSize;
        used += n;
    }
}
layout(constant_id = SNELL_SPEC_MAX_MEDIA) const int MAX_MEDIA = 1;
layout(constant_id = SNELL_SPEC_RAY_STACK) const uint RAY_STACK = 1u;
layout(constant_id = SNELL_SPEC_AMPLIFYING) const bool AMPLIFYING = false;
// Some material traps light, where it grows without end (ks.w of a material;
// render/Truncation.h, growthTraps): a pixel whose trees meet one may go on
// below the floor, so rays under the floor wait rather than being lost.
layout(constant_id = SNELL_SPEC_TRAPS) const bool TRAPS = false;
// Entries of an invocation's frontier: the rays a step leaves under its
// cut-off, which the next step traces on (0: a fixed tree, nothing deferred).
layout(constant_id = SNELL_SPEC_FRONTIER) const uint FRONTIER = 0u;
// Off (a preview inspection switch): no shadow rays, every light is seen.
layout(constant_id = SNELL_SPEC_SHADOWS) const bool SHADOWS = true;

// What the shader writes: the tile's pixels, row-major (a buffer: on lavapipe
// an imageStore in a loop costs 13x a buffer store; rgb the colour, a the
// pixel's truncation bound), and its own bookkeeping.
layout(set = 0, binding = SNELL_BINDING_OUTPUT, std430) writeonly buffer OutputBlock { OutputPixel outputPixels[]; };
// coherent: the shares' bits are read while other invocations clear them.
layout(set = 0, binding = SNELL_BINDING_COUNTERS, std430) coherent buffer CounterBlock { uint counters[]; };
#include "loop_budget.glsl"  // (it reports through the counters)
layout(set = 0, binding = SNELL_BINDING_SLOT_STATES, std430) buffer SlotStateBlock { SlotState slotStates[]; };
layout(set = 0, binding = SNELL_BINDING_RAY_STACK, std430) buffer RayStackBlock { PendingRay rayStack[]; };
layout(set = 0, binding = SNELL_BINDING_MEDIA_STACK, std430) buffer MediaStackBlock { uint mediaStack[]; };
layout(set = 0, binding = SNELL_BINDING_FRAME, std140) uniform FrameBlock { FrameParams frame; };
layout(push_constant) uniform TileBlock { TileParams tile; };
// Texel i of a scene buffer of floats.
#define texel(texels, i) uintBitsToFloat(texelFetch(texels, int(i)))
// The scene: texel buffers, each struct of shared_layout.h a run of texels,
// all RGBA32UI (floats by their bits: texel), since lavapipe compiles its
// fetch functions once for each format a view has (shared_layout.h).
layout(set = 0, binding = SNELL_BINDING_SPHERES) uniform utextureBuffer sphereTexels;
layout(set = 0, binding = SNELL_BINDING_SPHERE_MATERIALS) uniform utextureBuffer sphereMaterialTexels;
layout(set = 0, binding = SNELL_BINDING_ELLIPSOIDS) uniform utextureBuffer ellipsoidTexels;
layout(set = 0, binding = SNELL_BINDING_MATERIALS) uniform utextureBuffer materialTexels;
layout(set = 0, binding = SNELL_BINDING_LIGHTS) uniform utextureBuffer lightTexels;
layout(set = 0, binding = SNELL_BINDING_BVH) uniform utextureBuffer bvhTexels;
// The BVH's nodes again, the same buffer read through its device address,
// each word as two 64-bit halves (wide_words.glsl).
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BvhWords { u64vec2 words[]; };
// The ray and media stacks again, through their device addresses (a pending
// ray as four words of two halves).
layout(buffer_reference, std430, buffer_reference_align = 16) buffer PendingRays { u64vec2 words[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer MediaEntries { uint spheres[]; };
#ifdef SNELL_RAY_QUERY
layout(set = 0, binding = SNELL_BINDING_ACCELERATION) uniform accelerationStructureEXT sphereBoxes;
#endif
#ifdef SNELL_FP64
layout(set = 0, binding = SNELL_BINDING_SPHERE_BLOCK, std140) uniform SphereUniforms {
    SphereBlock small;
    SphereBlock smallLow;  // one block: a second uniform buffer crashes Mesa 22's llvmpipe here
};
#else
layout(set = 0, binding = SNELL_BINDING_SPHERE_BLOCK, std140) uniform SphereUniforms { SphereBlock small; };
#endif

// Scene values as the shader computes with them. In fp64 a value is its float
// pair hi + lo: the low parts live in twin buffers of the same layout.
#ifdef SNELL_FP64
layout(set = 0, binding = SNELL_BINDING_FRAME_LOW, std140) uniform FrameLowBlock { FrameParams frameLow; };
layout(set = 0, binding = SNELL_BINDING_SPHERES_LOW) uniform utextureBuffer sphereTexelsLow;
layout(set = 0, binding = SNELL_BINDING_ELLIPSOIDS_LOW) uniform utextureBuffer ellipsoidTexelsLow;
layout(set = 0, binding = SNELL_BINDING_LIGHTS_LOW) uniform utextureBuffer lightTexelsLow;
layout(set = 0, binding = SNELL_BINDING_RAY_STACK_LOW, std430) buffer RayStackLowBlock { PendingRay rayStackLow[]; };
#define WIDE(hi, lo) (dvec4(hi) + dvec4(lo))
// Texel i of a scene buffer and of its low twin (named ...Low).
#define FETCH(texels, i) WIDE(texel(texels, i), texel(texels##Low, i))
#else
#define WIDE(hi, lo) (hi)
#define FETCH(texels, i) texel(texels, i)
#endif
// A small scene's spheres come from a uniform buffer: loops over them read one
// sphere for the whole SIMD row, a scalar load, cheaper on lavapipe than a
// texel fetch (which serves eight lanes of any indices).
rvec4 sphereAnchor(uint i) {
    if (SPHERES_IN_BLOCK) return WIDE(small.spheres[i].anchorRadius, smallLow.spheres[i].anchorRadius);
    return FETCH(sphereTexels, 2u * i);
}
rvec4 sphereNormal(uint i) {
    if (SPHERES_IN_BLOCK) return WIDE(small.spheres[i].normal, smallLow.spheres[i].normal);
    return FETCH(sphereTexels, 2u * i + 1u);
}
rmat4 ellipsoidMatrix(uint e) {
    // Rows of the affine map; the matrix's columns are its rows transposed.
    return transpose(rmat4(FETCH(ellipsoidTexels, 3u * e), FETCH(ellipsoidTexels, 3u * e + 1u),
                           FETCH(ellipsoidTexels, 3u * e + 2u), rvec4(0.0, 0.0, 0.0, 1.0)));
}
layout(constant_id = SNELL_SPEC_LIGHTS_IN_FRAME) const bool LIGHTS_IN_FRAME = false;
rvec3 lightPosition(uint j) {
    if (LIGHTS_IN_FRAME) return WIDE(frame.lights[j].position, frameLow.lights[j].position).xyz;
    return FETCH(lightTexels, 2u * j).xyz;
}
vec3 lightColour(uint j) {
    if (LIGHTS_IN_FRAME) return frame.lights[j].colour.rgb;
    return texel(lightTexels, 2u * j + 1u).rgb;
}
// Four spheres' materials a texel.
uint sphereMaterial(uint i) {
    uvec4 four = texelFetch(sphereMaterialTexels, int(i / 4u));
    uint k = i % 4u;
    return k == 0u ? four.x : k == 1u ? four.y : k == 2u ? four.z : four.w;
}
vec4 materialKd(uint m) { return texel(materialTexels, 3u * m); }
vec4 materialKs(uint m) { return texel(materialTexels, 3u * m + 1u); }
vec4 materialKt(uint m) { return texel(materialTexels, 3u * m + 2u); }

const uint NONE = 0xffffffffu;

uint countedRays[SNELL_RAY_COUNTER_COUNT];


// ---------------------------------------------------------------------------
// Intersection: the maths is in intersect.glsl (shared with the test kernel);
// here the sphere is fetched and the ray's relation to it decided.

rvec4 preloadedAnchor[SNELL_MAX_UNROLLED_SPHERES];
rvec4 preloadedNormal[SNELL_MAX_UNROLLED_SPHERES];
// An unrolled ellipsoid's map (ELLIPSOID_MASK), read once per dispatch: its
// three texels fetched at every test (on lavapipe a call of ~64 instructions
// each, whatever the index) cost bench/simple a quarter of its dispatch.
rmat4 preloadedEllipsoid[SNELL_MAX_UNROLLED_SPHERES];
real intersectSphere(uint index, rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start) {
    uint mode = index == fromSphere ? start : ELSEWHERE;
    rvec4 anchor = SPHERE_COUNT > 0u ? preloadedAnchor[index] : sphereAnchor(index);
    rvec4 normal = SPHERE_COUNT > 0u ? preloadedNormal[index] : sphereNormal(index);
    bool ellipsoid = SPHERE_COUNT > 0u ? ((ELLIPSOID_MASK >> index) & 1u) != 0u : anchor.w < 0.0;
    if (HAS_ELLIPSOIDS && ellipsoid) {
        rmat4 objectFromWorld = SPHERE_COUNT > 0u ? preloadedEllipsoid[index] : ellipsoidMatrix(uint(-anchor.w) - 1u);
        return intersectEllipsoid(objectFromWorld, normal.w, origin, originLength, dir, mode);
    }
    return intersectTrueSphere(anchor, normal, origin, originLength, dir, mode);
}

// Word i of the BVH's nodes, through whichever the driver reads faster: the
// texel view or the buffer's device address (shared_layout.h).
uvec4 bvhWord(int i) {
    if (BVH_WORDS) return fromHalves(BvhWords(uvec2(frame.bvhAddressLow, frame.bvhAddressHigh)).words[i]);
    return texelFetch(bvhTexels, i);
}

#include "bvh_walk.glsl"

uint traverseBvh(rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start, bool anyHit,
                 inout real tHit) {
    rvec3 inverseDir = safeInverse(dir);
    uint hit = NONE;
    uint entry = 0u;
    uint depth = 0u;
    bool walking = true;
    while (walking) {
        tick(1u);
        if (COUNT_LANES) countLanes(true, walkSlots, walkBusy);
        walkPass(entry, depth, walking, tHit, hit, origin, originLength, dir, inverseDir, fromSphere, start, anyHit);
    }
    return hit;
}

#ifdef SNELL_RAY_QUERY
// The same search through the driver's traversal (VK_KHR_ray_query; on a GPU
// with ray-tracing hardware, that hardware): it reports each sphere whose box
// (rounded outwards, so it holds the sphere) the ray enters within tHit, and
// the exact test of intersect.glsl, with its no-epsilon rules, decides as in
// the walk above. A hit nearer than tHit is handed back to the query, which
// then culls the boxes beyond it.
uint queryBoxes(rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start, bool anyHit,
                inout real tHit) {
    rayQueryEXT query;
    rayQueryInitializeEXT(query, sphereBoxes, gl_RayFlagsNoneEXT, 0xffu, origin, 0.0, dir, tHit);
    uint hit = NONE;
    while (rayQueryProceedEXT(query)) {
        tick(1u);
        if (COUNT_LANES) countLanes(true, walkSlots, walkBusy);
        uint i = uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, false));
        real t = intersectSphere(i, origin, originLength, dir, fromSphere, start);
        if (t < tHit) {
            tHit = t;
            hit = i;
            rayQueryGenerateIntersectionEXT(query, t);
            if (anyHit) rayQueryTerminateEXT(query);
        }
    }
    return hit;
}
#endif

// The BVH search of this build: the driver's traversal, else snell's walk.
uint searchBvh(rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start, bool anyHit,
               inout real tHit) {
#ifdef SNELL_RAY_QUERY
    return queryBoxes(origin, originLength, dir, fromSphere, start, anyHit, tHit);
#else
    return traverseBvh(origin, originLength, dir, fromSphere, start, anyHit, tHit);
#endif
}

// SPEC §4.1: the closest hit with t > 0; returns the sphere index or NONE.
uint closestHit(rvec3 origin, rvec3 dir, uint fromSphere, uint start, out real tHit) {
    tHit = NO_HIT;
    real originLength = length(origin);
    if (USE_BVH) return searchBvh(origin, originLength, dir, fromSphere, start, false, tHit);
    uint hit = NONE;
    if (SPHERE_COUNT > 0u) {
        [[unroll]] for (uint i = 0u; i < SPHERE_COUNT; ++i) {
            real t = intersectSphere(i, origin, originLength, dir, fromSphere, start);
            if (t < tHit) { tHit = t; hit = i; }
        }
        return hit;
    }
    for (uint i = 0u; i < frame.sphereCount; ++i) {
        tick(1u);
        real t = intersectSphere(i, origin, originLength, dir, fromSphere, start);
        if (t < tHit) { tHit = t; hit = i; }
    }
    return hit;
}

// SPEC §4.3 visibility: does any surface cross the open segment (0, distance)?
// Stops at the first occluder.
// A ray that starts on a sphere headed into it (shading a hit from inside)
// crosses that sphere at its chord unless the light is nearer: that one test
// first spares the search its answer. (Not where the spheres are unrolled: a
// dynamic index into them costs more than it spares.)
bool crossesOwnSphere(rvec3 origin, real originLength, rvec3 dir, real distance, uint fromSphere, uint start) {
    return (USE_BVH || SPHERE_COUNT == 0u) && start == ENTERING &&
           intersectSphere(fromSphere, origin, originLength, dir, fromSphere, start) < distance;
}

bool occluded(rvec3 origin, rvec3 dir, real distance, uint fromSphere, uint start) {
    real originLength = length(origin);
    if (crossesOwnSphere(origin, originLength, dir, distance, fromSphere, start)) return true;
    if (USE_BVH) return searchBvh(origin, originLength, dir, fromSphere, start, true, distance) != NONE;
    bool blocked = false;
    if (SPHERE_COUNT > 0u) {
        [[unroll]] for (uint i = 0u; i < SPHERE_COUNT; ++i) {
            if (!blocked) blocked = intersectSphere(i, origin, originLength, dir, fromSphere, start) < distance;
        }
        return blocked;
    }
    for (uint i = 0u; i < frame.sphereCount && !blocked; ++i) {
        tick(1u);
        blocked = intersectSphere(i, origin, originLength, dir, fromSphere, start) < distance;
    }
    return blocked;
}

// ---------------------------------------------------------------------------
// The ray tree (SPEC §4), depth first on an explicit stack kept per invocation
// in rayStack/mediaStack, so an invocation can suspend between dispatches.
// Each pending ray carries its weight, depth, the sphere it starts on, whether
// it heads into that sphere, and its medium stack (innermost last).

// cutOff: that of the pixel in hand, the minimum weight or, under a
// tolerance, the one its current step uses (SlotState.cutOff). (The
// per-pixel values live in main's locals and are passed down: Mesa 22.3's
// llvmpipe keeps memory for every dispatch of a shader with such private
// globals, tests/soak_test.sh.)
bool worthTracing(vec3 w, float cutOff) {
    float m = max(w.x, max(w.y, w.z));
    return m > 0.0 && m >= cutOff;
}
// weight ⊙ colour, where a weight grown to +inf (an amplifying tree, SPEC §4)
// times 0 is 0, not NaN.
vec3 weighted(vec3 weight, vec3 colour) {
    bvec3 zero = bvec3(uvec3(equal(colour, vec3(0.0))) | uvec3(equal(weight, vec3(0.0))));
    return mix(weight * colour, vec3(0.0), zero);
}
#define INFINITY uintBitsToFloat(0x7f800000u)
// The largest weight a ray carries: an amplifying tree's weights grow without
// end and would overflow to +inf (then inf · 0 = NaN). A capped weight is at
// most the true one, so every sum stays a lower bound of the exact colour
// (render/Truncation.h); its twin is in CpuRenderer.cpp.
const float MAX_WEIGHT = 1e30;

// The ray being traced lives in registers; only a deferred child (the
// reflected one, when a ray also refracts) goes to the stack in device memory,
// and so does the current ray when the invocation suspends.
struct Ray {
    rvec3 origin;
    rvec3 dir;
    vec3 weight;      // product of the ks/kt factors along its path
    uint depth;
    uint fromSphere;  // the sphere whose surface it starts on
    bool inward;      // it heads into that sphere
    uint mediaCount;  // its medium stack is `media`, innermost last
    uint resumeShading;  // 0: not shaded yet; k > 0: shading resumes at light k − 1
};
// The medium stack of the ray in hand, innermost last. Every access is in a
// loop unrolled over MAX_MEDIA, so each entry has a constant index and the
// array lives in registers rather than in scratch memory.
uint media[MAX_MEDIA];
uint mediumAt(uint k) {
    uint sphere = NONE;
    [[unroll]] for (int i = 0; i < MAX_MEDIA; ++i)
        if (uint(i) == k) sphere = media[i];
    return sphere;
}

// Where a ray met its closest surface, and what shading needs there.
struct Hit {
    uint sphere;
    vec4 kd;          // the material, fetched once (shared_layout.h: Material)
    vec4 ks;
    vec4 kt;
    rvec3 point;
    rvec3 normal;     // the shading normal N (against the ray)
    bool fromOutside; // the ray arrived from outside the sphere
};

float etaOfSphere(uint sphere) { return materialKt(sphereMaterial(sphere)).w; }

// An invocation's entries in the ray and media buffers: its stack of
// RAY_STACK entries, then its frontier of FRONTIER, entry k of every
// invocation side by side (k · invocations + slot). Side by side, the lanes of
// a subgroup touch neighbouring memory (coalesced on a GPU), and a render
// whose rays wait in few entries touches few pages: laid out an invocation
// after another, each invocation's first frontier entry was a page of its own,
// and on lavapipe faulting those pages in cost 1–2 ms a render.
uint invocations;  // of this dispatch (main)
// This workgroup's share of the tile's pixels (takePixel). lavapipe runs
// each thread's workgroups from one contiguous range of IDs, so with share =
// ID the threads took the tile's column stripes side by side: a 1024-wide
// tile with its glass on the left ran on one thread. A stride coprime with
// the count near count / golden ratio spreads each range over the tile.
uint share;
uint helpedShare;  // the share the invocation takes its pixels from (takePixel)
uint stackEntry(uint slot, uint k) { return k * invocations + slot; }
uint frontierEntry(uint slot, uint k) { return (RAY_STACK + k % max(FRONTIER, 1u)) * invocations + slot; }

// The stacks' entries, through whichever the driver reads and writes faster
// at per-lane indices: Mesa 25's lavapipe checks each lane's offset into a
// storage buffer against its size, where through an address a load is one
// masked gather a component, and the stack's traffic measured 1.05–1.25×
// faster; Mesa 22.3 goes lane by lane there (docs/performance.md, "The ray
// stack through its address"). Without the buffer's checks an entry past the
// end would not be dropped: spawnChildren keeps within RAY_STACK (stackFull).
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

void storeRay(uint entry, Ray r) {
#ifdef SNELL_FP64
    vec3 origin, originLow, dir, dirLow;
    splitDouble(r.origin, origin, originLow);
    splitDouble(r.dir, dir, dirLow);
    rayStackLow[entry].origin = vec4(originLow, 0.0);
    rayStackLow[entry].direction = vec4(dirLow, 0.0);
#else
    vec3 origin = r.origin, dir = r.dir;
#endif
    storePending(entry, PendingRay(vec4(origin, 0.0), vec4(dir, 0.0), vec4(r.weight, 0.0), r.depth, r.fromSphere,
                                   (r.inward ? 1u : 0u) | (r.mediaCount << 1), r.resumeShading));
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k)
        if (uint(k) < r.mediaCount) storeMedium(entry * uint(MAX_MEDIA) + uint(k), media[k]);
}

Ray loadRay(uint entry) {
    PendingRay p = loadPending(entry);
    uint mediaCount = p.flags >> 1;
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k)
        if (uint(k) < mediaCount) media[k] = loadMedium(entry * uint(MAX_MEDIA) + uint(k));
    return Ray(WIDE(p.origin, rayStackLow[entry].origin).xyz, WIDE(p.direction, rayStackLow[entry].direction).xyz,
               p.weight.rgb, p.depth, p.fromSphere, (p.flags & 1u) != 0u, mediaCount, p.resumeShading);
}

void pushRay(uint slot, inout uint pending, Ray r) {
    storeRay(stackEntry(slot, pending), r);
    pending++;
}

Ray popRay(uint slot, inout uint pending) {
    pending--;
    return loadRay(stackEntry(slot, pending));
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
    if (FRONTIER > 0u && state.frontierCount < FRONTIER && (mayGoBelowFloor || m >= frame.minWeight)) {
        storeRay(frontierEntry(slot, state.frontierHead + state.frontierCount), r);
        state.frontierCount++;
        state.deferred.rgb += r.weight;
        state.heaviestLeft = max(state.heaviestLeft, m);
    } else {
        // Light that may grow, lost for want of room (the CPU reference keeps
        // it): no estimate of the pixel's error holds.
        if (mayGoBelowFloor && FRONTIER > 0u) state.droppedGrowing = 1u;
        state.lost.rgb += r.weight;
    }
}

// The cut-off that decides whether a ray is traced now: the step's, while the
// frontier has room for what it leaves; the floor once it is full (the ray is
// traced now rather than lost: the tree only grows, and no step traces any
// ray twice).
float tracingCutOff(SlotState state, float cutOff) {
    return FRONTIER > 0u && state.frontierCount >= FRONTIER ? frame.minWeight : cutOff;
}

// 1–2. The closest hit of ray r: on a miss the background is added to the
// pixel and false returned; on a hit, where and how it was hit. A ray that
// resumes shading (resumeShading > 0) finds the same hit again.
bool findHit(Ray r, vec3 weight, inout vec3 sum, out Hit h) {
    real t;
    h.sphere = closestHit(r.origin, r.dir, r.fromSphere, r.inward ? ENTERING : LEAVING, t);
    if (h.sphere == NONE) {
        sum += weighted(weight, frame.background.rgb);
        return false;
    }
    uint material = sphereMaterial(h.sphere);
    h.kd = materialKd(material);
    h.ks = materialKs(material);
    h.kt = HAS_REFRACTION ? materialKt(material) : vec4(0.0);
    // The hit point o + t d, not re-projected onto the surface: re-projecting
    // (centre + r n̂, or normalising the object-space point) rounds at the
    // scale of the centre or of the largest semi-axis, which for a big floor
    // sphere near the camera is 100× the error of o + t d. Self-intersection
    // needs no point exactly on the surface (see intersectSphere).
    rvec3 o = r.origin;
    rvec3 d = r.dir;
    h.point = o + t * d;
    rvec4 anchor = sphereAnchor(h.sphere);
    rvec3 outward;
    if (HAS_ELLIPSOIDS && anchor.w < 0.0) {
        rmat4 objectFromWorld = ellipsoidMatrix(uint(-anchor.w) - 1u);
        rvec3 p = (objectFromWorld * rvec4(o, 1.0)).xyz + t * (rmat3(objectFromWorld) * d);
        outward = normalize(transpose(rmat3(objectFromWorld)) * p);
    } else {
        outward = normalize(o - anchor.xyz + t * d + anchor.w * sphereNormal(h.sphere).xyz);
    }
    h.fromOutside = dot(d, outward) < 0.0;
    h.normal = h.fromOutside ? outward : -outward;
    return true;
}

// 3. Light j's part of the local Phong term (SPEC §4.3) where the light is
// seen: l, the unit vector towards it, with n·l = nl > 0; v towards the eye.
vec3 lightTerm(uint j, Hit h, rvec3 l, float nl, rvec3 v) {
    float rv = float(dot(2.0 * dot(h.normal, l) * h.normal - l, v));
    float specular = rv > 0.0 ? pow(rv, h.kd.w) : 0.0;
    return lightColour(j) * (h.kd.rgb * nl + h.ks.rgb * specular);
}
// The unit vector l from a point towards light j; returns the distance.
real lightDirection(uint j, rvec3 point, out rvec3 l) {
    l = lightPosition(j) - point;
    real distance = length(l);
    l *= 1.0 / distance;  // one division, not three
    return distance;
}
// The same from hit h, and n·l.
float towardsLight(uint j, Hit h, out rvec3 l, out real distance) {
    distance = lightDirection(j, h.point, l);
    return float(dot(h.normal, l));
}
// How a shadow ray from hit h starts on its sphere: towards N's side it
// enters the sphere only when N = −No (the hit was from inside).
uint shadowStart(Hit h) { return h.fromOutside ? LEAVING : ENTERING; }

// Light j's part of the local term with binary shadows (SPEC §4.3).
vec3 shadeLight(uint j, Hit h, rvec3 v, inout uint shadowRays) {
    rvec3 l;
    real distance;
    float nl = towardsLight(j, h, l, distance);
    if (!(nl > 0.0)) return vec3(0.0);
    if (COUNT_RAYS && SHADOWS) countedRays[SNELL_COUNTER_SHADOW]++;
    if (SHADOWS) shadowRays++;
    if (SHADOWS && occluded(h.point, l, distance, h.sphere, shadowStart(h))) return vec3(0.0);
    return lightTerm(j, h, l, nl, v);
}

// The position of the n-th (from 0) set bit of x: a binary search.
uint nthSetBit(uint x, uint n) {
    uint position = 0u;
    [[unroll]] for (uint width = 16u; width > 0u; width >>= 1u) {
        uint below = uint(bitCount(x & ((1u << width) - 1u)));
        if (n >= below) {
            n -= below;
            x >>= width;
            position += width;
        }
    }
    return position;
}

#ifndef SNELL_RAY_QUERY  // (shared shadow rays walk snell's own BVH)
// What a lane that walks another's shadow ray needs of that lane's hit:
// the point and its length, the sphere and how the ray starts on it. A slot
// for each invocation of the workgroup, by subgroup and lane.
shared rvec4 sharedHitPoint[SNELL_WORKGROUP_SIZE];
shared uint sharedHitSphere[SNELL_WORKGROUP_SIZE];
uint sharedSlot(uint lane) { return gl_SubgroupID * gl_SubgroupSize + lane; }

// The lights' part of the local term of a hit, the subgroup's shadow rays
// shared out among its lanes. In the lights' own loop a lane walks only its own
// shadow ray, so a lane whose ray missed, whose light is behind its surface or
// whose ray leaves through its own sphere idles while the others walk (on
// SphereFlake2 1.6 lanes of 8 walked on average, 19 % of the lane slots of
// those walks busy). Here the lights go in batches of min(4, 32 / subgroup
// size): bit lane · batch + b of `casting` says that the lane casts a ray to
// the batch's light b, and the k-th of those rays is walked by the (k mod n)-th
// of the n lanes still in the pixel loop, each walking its rays one after
// another in one loop. No lane talks to another inside the walk (rays handed
// out there to whichever lanes were idle, by ballots and shuffles, cost more
// than they saved on lavapipe; docs/performance.md): a lane reads the hit of
// the ray's owner from workgroup memory, and after the walk one reduction tells
// each owner, by the same bits, which of its rays were blocked. It adds each
// seen light's term in light order: the same sums as shadeLight's loop. The
// host enables this on CPU devices with subgroups of up to 16 lanes only: there
// a subgroup's lanes run in lockstep, so each sees the others' hits once
// written and all meet again at the reductions after the walk (a GPU would need
// subgroup barriers), and its slots below lie within the workgroup. And without
// a loop budget only: a dispatch cannot suspend in the middle of a walk.
void shadeLightsShared(inout SlotState state, Ray r, vec3 weight, Hit h, bool shading, inout uint shadowRays) {
    rvec3 v = -r.dir;
    uint start = shadowStart(h);
    real originLength = length(h.point);
    const uint size = gl_SubgroupSize;
    const uint lane = gl_SubgroupInvocationID;
    const uint batch = min(4u, 32u / size);
    if (shading) {
        sharedHitPoint[sharedSlot(lane)] = rvec4(h.point, originLength);
        sharedHitSphere[sharedSlot(lane)] = h.sphere * 4u + start;
    }
    subgroupMemoryBarrierShared();
    // The walkers: every lane still in the pixel loop, in lane order.
    uint inLoop = subgroupOr(1u << lane);
    const uint walkers = uint(bitCount(inLoop)), walkerRank = uint(bitCount(inLoop & ((1u << lane) - 1u)));
    for (uint firstLight = 0u; firstLight < frame.lightCount; firstLight += batch) {
        // The rays to walk: those towards lights the surface faces, less those
        // that cross the hit sphere first.
        uint casting = 0u;
        [[unroll]] for (uint b = 0u; b < 4u; ++b) {
            bool walks = false;
            if (shading && b < batch && firstLight + b < frame.lightCount) {
                rvec3 l;
                real distance;
                if (towardsLight(firstLight + b, h, l, distance) > 0.0) {
                    if (COUNT_RAYS) countedRays[SNELL_COUNTER_SHADOW]++;
                    shadowRays++;
                    walks = !crossesOwnSphere(h.point, originLength, l, distance, h.sphere, start);
                }
            }
            if (walks) casting |= 1u << b;
        }
        casting = subgroupOr(casting << (lane * batch));
        uint rays = uint(bitCount(casting));
        uint walkedBlocked = 0u;
        uint ray = walkerRank, bit = 0u, entry = 0u, depth = 0u, hit = NONE, fromSphere = 0u, fromStart = 0u;
        rvec3 origin = rvec3(0.0), l = rvec3(0.0), inverseDir = rvec3(0.0);
        real distance = 0.0, rayOriginLength = 0.0;
        bool walking = ray < rays, begins = walking;
        while (walking) {
            if (begins) {
                begins = false;
                // A ray to begin: its owner's hit, and the direction to its light.
                bit = nthSetBit(casting, ray);
                rvec4 point = sharedHitPoint[sharedSlot(bit / batch)];
                uint from = sharedHitSphere[sharedSlot(bit / batch)];
                origin = point.xyz;
                rayOriginLength = point.w;
                fromSphere = from >> 2;
                fromStart = from & 3u;
                distance = lightDirection(firstLight + bit % batch, origin, l);
                inverseDir = safeInverse(l);
                hit = NONE;
            }
            if (COUNT_LANES) countLanes(true, walkSlots, walkBusy);
            walkPass(entry, depth, walking, distance, hit, origin, rayOriginLength, l, inverseDir, fromSphere,
                     fromStart, true);
            if (!walking) {
                if (hit != NONE) walkedBlocked |= 1u << bit;
                ray += walkers;
                walking = begins = ray < rays;
                entry = 0u;
                depth = 0u;
            }
        }
        uint blocked = subgroupOr(walkedBlocked);
        // Each lane's seen lights, in light order: those it cast a ray to
        // (so its surface faces them) that nothing blocked.
        [[unroll]] for (uint b = 0u; b < 4u; ++b) {
            if (b >= batch) continue;
            uint mine = 1u << (lane * batch + b);
            if ((casting & mine) == 0u || (blocked & mine) != 0u) continue;
            rvec3 toLight;
            real lightDistance;
            float nl = towardsLight(firstLight + b, h, toLight, lightDistance);
            state.sum.rgb += weighted(weight, lightTerm(firstLight + b, h, toLight, nl, v));
        }
    }
}
#endif

// What a step of a pixel proves of its exact colour: its colour is a lower
// bound and its colour plus the weight it has not traced times the radiance
// bound an upper bound; the pixel keeps the best of each (render/Truncation.h,
// PixelEstimate, its twin). Returns the bound on the clamped colour.
float addStep(inout SlotState state, float samples, out bool unbounded) {
    vec3 value = state.sum.rgb / samples;
    vec3 notTraced = state.lost.rgb + state.deferred.rgb;
    state.lower.rgb = max(state.lower.rgb, value);
    state.upper.rgb = min(state.upper.rgb, value + weighted(notTraced, frame.radiance.rgb) / samples);
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

// 4–5. The children of ray r at hit h: reflection (keeps the medium stack) and
// refraction (SPEC §4.5). Returns whether r is now a child to trace next, the
// other child having been pushed on the stack; refraction is traced first, as
// in the CPU reference. A child under the cut-off waits in the frontier
// (deferRay); weight the depth limit stops is lost (render/Truncation.h).
bool spawnChildren(uint slot, inout SlotState state, inout Ray r, vec3 weight, Hit h, float cutOff) {
    vec3 reflectedGain = HAS_REFLECTION ? h.ks.rgb : vec3(0.0);
    if (r.depth >= frame.maxDepth) {
        state.lost.rgb += weighted(weight, reflectedGain + (HAS_REFRACTION ? h.kt.rgb : vec3(0.0)));
        return false;
    }
    rvec3 d = r.dir;
    rvec3 n = h.normal;
    noteGain(state, h, reflectedGain + (HAS_REFRACTION ? h.kt.rgb : vec3(0.0)), weight);
    vec3 reflectedWeight = min(weighted(weight, reflectedGain), vec3(MAX_WEIGHT));
    bool transmits = false;  // a refracted ray exists (no total internal reflection)
    rvec3 refracted = rvec3(0.0);
    vec3 transmittedWeight = vec3(0.0);
    uint removeAt = r.mediaCount;  // leaving: where this sphere is in the stack
    vec4 kt = h.kt;
    if (HAS_REFRACTION && max(kt.r, max(kt.g, kt.b)) > 0.0) {
        transmittedWeight = min(weighted(weight, kt.rgb), vec3(MAX_WEIGHT));
        // Snell's law, SPEC §4.5.
        real eta = relativeIndex(r, h, removeAt);
        real c = -dot(n, d);
        real k = 1.0 - eta * eta * (1.0 - c * c);
        if (k < 0.0) {
            // Total internal reflection is the reflected ray in the same medium:
            // one ray carries both weights.
            reflectedWeight = min(reflectedWeight + transmittedWeight, vec3(MAX_WEIGHT));
        } else {
            transmits = true;
            refracted = normalize(eta * d + (eta * c - sqrt(k)) * n);
        }
    }
    bool reflects = (HAS_REFLECTION || HAS_REFRACTION) && worthTracing(reflectedWeight, tracingCutOff(state, cutOff));
    Ray reflectedRay = Ray(h.point, d - 2.0 * dot(d, n) * n, reflectedWeight, r.depth + 1u, h.sphere, !h.fromOutside,
                           r.mediaCount, 0u);
    if (!reflects && (HAS_REFLECTION || HAS_REFRACTION)) deferRay(slot, state, reflectedRay);
    // Asked after the reflected child waits: should it have filled the
    // frontier, the refracted child is traced down to the floor, not lost.
    bool refracts = transmits && worthTracing(transmittedWeight, tracingCutOff(state, cutOff));
    if (reflects && COUNT_RAYS) countedRays[SNELL_COUNTER_REFLECTED]++;
    if (refracts && COUNT_RAYS) countedRays[SNELL_COUNTER_REFRACTED]++;
    if (!transmits) {
        r = reflectedRay;
        return reflects;
    }
    // Both children: the lighter is traced next and the heavier waits on the
    // stack, so each waiting ray at least halves (ks + kt <= 1) the weight of
    // the path below it, and the stack needs no more than log(cut-off) / log(q)
    // entries however deep the tree (host/gpu/ComputeRenderer.cpp sizes it).
    // In an amplifying scene (where the stack is sized by depth anyway) the
    // heavier goes on instead: under a tree budget the weightiest rays are
    // traced first, which is what saturates a diverging channel.
    bool both = reflects && refracts;
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
        if (stackFull) state.lost.rgb += reflectedWeight;
        else pushRay(slot, state.pending, reflectedRay);  // with the parent's media, still current
    }
    // The refracted ray's medium stack replaces the parent's (kept when the
    // reflected ray goes on with it).
    uint parentMedia[MAX_MEDIA];
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k) parentMedia[k] = media[k];
    uint count = crossSurface(h, r.mediaCount, removeAt);
    Ray refractedRay = Ray(h.point, refracted, transmittedWeight, r.depth + 1u, h.sphere, h.fromOutside, count, 0u);
    if (refracts && !refractedWaits) {
        r = refractedRay;  // traced next, with its medium stack
        return true;
    }
    if (!refracts) deferRay(slot, state, refractedRay);
    else if (stackFull) state.lost.rgb += transmittedWeight;
    else pushRay(slot, state.pending, refractedRay);
    // The reflected ray goes on (if it is traced at all), with the parent's media.
    [[unroll]] for (int k = 0; k < MAX_MEDIA; ++k) media[k] = parentMedia[k];
    r = reflectedRay;
    return reflects;
}

// SPEC §3: sub-pixel sample k of pixel p: the ray through
// (i + (a+½)/s, j + (b+½)/s), from the eye, starting at distance D along it.
Ray cameraRay(uvec2 p, uint k) {
    // k = b·s + a with k < s² ≤ 64²: b is exact from float division.
    float s = float(frame.supersample);
    float b = floor((float(k) + 0.5) / s);
    rvec2 ab = rvec2(float(k) - b * s, b);
    rvec2 q = rvec2(p) + (ab + 0.5) / real(s);
    rvec3 corner = WIDE(frame.cornerDir, frameLow.cornerDir).xyz;
    rvec3 right = WIDE(frame.pixelRight, frameLow.pixelRight).xyz;
    rvec3 down = WIDE(frame.pixelDown, frameLow.pixelDown).xyz;
    rvec3 dir = normalize(corner + q.x * right + q.y * down);
    rvec4 primaryStart = WIDE(frame.primaryStart, frameLow.primaryStart);
    return Ray(primaryStart.xyz + primaryStart.w * dir, dir, vec3(1.0), 0u, NONE, false, 0u, 0u);
}

// ---------------------------------------------------------------------------
// The pixel loop's steps. What a dispatch fixes for all of them, set once at
// the start of main:
uint tilePixels;     // the tile's pixels
float tolerance;     // on each pixel's truncation bound; 0: a fixed tree
float floorCutOff;   // the lowest cut-off (the fixed tree's cut-off without a tolerance)
float firstCutOff;   // a pixel's first step's
uint samples;        // sub-pixel samples a pixel traces
uint pixelBudget;    // rays a pixel's trees may trace; 0: no limit
float saturation;    // a channel's sum where it is final (amplifying scenes)

SlotState freshPixel(uint pixelIndex) {
    return SlotState(vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0), vec4(INFINITY), vec4(0.0), pixelIndex, 0u, 0u, 0u,
                     0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u, firstCutOff, 0.0, INFINITY, INFINITY, 0.0, 0u, 0u, 0u);
}

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
    state.heaviestLeft = 0.0;
    state.frontierOld = state.frontierCount;
}

// The invocation's next pixel of the tile. The tile is dealt in W shares of
// runs of a workgroup's size (run r to share r mod W), one share a
// workgroup, each with its counter of pixels taken, on a cache line of its
// own (one counter for the whole tile moved between the cores at every
// pixel, which cost more than it won on cheap scenes). An invocation takes
// the next pixel of its workgroup's share not yet taken, so while the share
// has pixels left no lane idles beside a lane whose pixel is expensive (a
// fixed share each left most lanes of a subgroup waiting on the one with the
// deep glass tree or the long BVH walks). Where trees diverge (refraction, a
// BVH) an invocation whose share is taken helps with the other workgroups'
// in turn, so no lane and no core idles while any share has pixels left:
// the end of each share no longer leaves its lanes idle, nor the end of the
// tile a core. (lavapipe runs a workgroup to its end on one thread: a
// workgroup goes on through the shares of those queued behind it, which
// then find them taken.) Elsewhere it stops: on gonzalez-originalTest,
// cheap and even, helping cost 15–21 % (docs/performance.md). The host
// decides (ComputeRenderer::specialise) and reads the tile's progress by it.
layout(constant_id = SNELL_SPEC_HELPS) const bool HELPS = false;
uint takeFromHelpedShare() {
    const uint size = uint(SNELL_WORKGROUP_SIZE);
    uint taken = atomicAdd(counters[SNELL_COUNTER_COUNT + helpedShare * SNELL_COUNTER_STRIDE], 1u);
    return taken / size * invocations + helpedShare * size + taken % size;
}
// Which shares may have pixels left, as bits (shared_layout.h): a bit a
// share, and above them a bit a word of those, set while the word is not 0.
// They spare a helper an atomic on every share taken: on a GPU, thousands of
// workgroups each walking thousands of shares cost more than the tile.
uint shareWords() { return SNELL_SHARE_WORDS(gl_NumWorkGroups.x); }
// The counter holding share s's bit, and that holding share word w's bit.
uint shareBitsAt(uint s) { return SNELL_SHARE_BITS_AT(gl_NumWorkGroups.x) + s / 32u; }
uint wordBitsAt(uint w) { return SNELL_WORD_BITS_AT(gl_NumWorkGroups.x) + w / 32u; }
// Share s has no pixel left: its bit cleared, and its word's once that is 0
// (the clear that empties a word is the one that sees it go).
void shareTaken(uint s) {
    uint old = atomicAnd(counters[shareBitsAt(s)], ~(1u << (s % 32u)));
    if (old == 1u << (s % 32u)) atomicAnd(counters[wordBitsAt(s / 32u)], ~(1u << (s / 32u % 32u)));
}
// The first share word at or after word w, in turn, whose bit is set; NONE where none is.
uint nextWordLeft(uint w) {
    const uint count = (shareWords() + 31u) / 32u;
    uint k = w / 32u;
    uint bits = counters[wordBitsAt(w)] & ~((1u << (w % 32u)) - 1u);
    tick(1u);  // the pass that ends the loop (loop_budget.glsl)
    for (uint n = 0u; n <= count; ++n) {
        tick(1u);
        if (bits != 0u) return k * 32u + uint(findLSB(bits));
        k = k + 1u == count ? 0u : k + 1u;
        bits = counters[wordBitsAt(k * 32u)];
    }
    return NONE;
}
// The next share after s, in turn, that may have pixels left; NONE where none has.
uint nextShareLeft(uint s) {
    uint rest = counters[shareBitsAt(s)] & ~((2u << (s % 32u)) - 1u);
    if (rest != 0u) return s / 32u * 32u + uint(findLSB(rest));
    const uint words = shareWords();
    uint w = s / 32u;
    tick(2u);  // the pass that ends the loop, and nextWordLeft's in it
    for (uint n = 0u; n <= words; ++n) {
        tick(1u);
        w = nextWordLeft(w + 1u == words ? 0u : w + 1u);
        if (w == NONE) return NONE;
        uint bits = counters[shareBitsAt(w * 32u)];
        if (bits != 0u) return w * 32u + uint(findLSB(bits));
        // Emptied since its word's bit was read: on past it.
    }
    return NONE;
}
uint takePixel() {
    uint pixel = takeFromHelpedShare();
    if (!HELPS) return min(pixel, tilePixels);
    // Each failed take clears its share's bit, and bits are only cleared, so
    // this ends. These loops count towards the loop budget like the others.
    tick(3u);  // the pass that ends the loop, and those of the two loops in it
    while (pixel >= tilePixels) {
        tick(1u);
        shareTaken(helpedShare);
        uint next = nextShareLeft(helpedShare);
        if (next == NONE) return tilePixels;
        helpedShare = next;
        pixel = takeFromHelpedShare();
    }
    return pixel;
}

// The finished pixel written out (render/Truncation.h: its colour, bound and
// how it stopped), and the invocation moved on to its next pixel.
void finishPixel(uint slot, inout SlotState state, StepOutcome o, uint shadowRays) {
    // A pixel that dropped light that may grow, and has not saturated, has
    // neither a bound nor an estimate: it is over the tolerance, and says why.
    bool dropped = state.droppedGrowing != 0u && o.unbounded;
    bool overTolerance = tolerance > 0.0 && !o.certified && (!o.settled || dropped);
    outputPixels[state.pixel] = OutputPixel(
        vec4(state.lower.rgb, o.unbounded ? -o.bound : o.bound),
        vec4(o.settled && !dropped ? o.estimate : -1.0, float(state.overBudget),
             dropped ? 2.0 : overTolerance ? 1.0 : 0.0, float(state.treeRays)));
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

// The image's pixel of the tile's pixel p (TileParams).
uvec2 imagePixel(uvec2 p) {
    const uvec2 run = uvec2(SNELL_TILE_COLUMN_RUN, SNELL_TILE_ROW_RUN);
    uvec2 inRun = p % run;
    return uvec2(tile.originX, tile.originY) + (p - inRun) * uvec2(tile.strideX, tile.strideY) + inRun;
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
        ray = cameraRay(imagePixel(pixel), frame.firstSample + state.started);
        state.started++;
        if (COUNT_RAYS) countedRays[SNELL_COUNTER_PRIMARY]++;
        return true;
    }
    return false;
}

// The dispatch's constants (above) from the frame and the tile, its counts
// zeroed, and the spheres of a small scene preloaded.
void beginDispatch() {
    invocations = gl_NumWorkGroups.x * uint(SNELL_WORKGROUP_SIZE);
    share = gl_WorkGroupID.x * max(tile.workgroupStride, 1u) % gl_NumWorkGroups.x;
    helpedShare = share;
    tilePixels = tile.width * tile.height;
    [[unroll]] for (int k = 0; k < SNELL_RAY_COUNTER_COUNT; ++k) countedRays[k] = 0u;
    [[unroll]] for (uint i = 0u; i < SPHERE_COUNT; ++i) {
        preloadedAnchor[i] = sphereAnchor(i);
        preloadedNormal[i] = sphereNormal(i);
        if (HAS_ELLIPSOIDS && ((ELLIPSOID_MASK >> i) & 1u) != 0u)
            preloadedEllipsoid[i] = ellipsoidMatrix(uint(-preloadedAnchor[i].w) - 1u);
    }
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

// 1–2. Ray r of the pixel: under the cut-off it waits in the frontier, past
// the tree budget it is lost; else its closest hit, with the background on a
// miss or the ambient term on a hit added to the pixel. True where it hit
// (h, and the weight it carries), to be shaded. A ray that resumes shading
// keeps the weight it started with and adds nothing twice.
bool traceRay(uint slot, inout SlotState state, inout Ray r, float cutOff, out vec3 weight, out Hit h,
              inout uint deepest) {
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
        state.lost.rgb += weight;
        return false;
    }
    if (!resuming) {
        state.treeRays++;
        state.rays++;
    }
    vec3 sum = state.sum.rgb;
    bool hit = findHit(r, weight, sum, h);
    if (hit && !resuming) sum += weighted(weight, frame.ambient.rgb * h.kd.rgb);
    state.sum.rgb = sum;
    deepest = max(deepest, r.depth);
    return hit;
}

// 3. The lights' part of the local term of ray r at hit h, each light added
// to the pixel as it is shaded, in light order (the same sums whether or not
// shading is suspended part-way). Under a loop budget every lane runs this
// loop (shading or not), so the subgroup can check its budget between lights:
// one ray's shading may take any number of lights, over several dispatches.
// Rays that resume start where they stopped: the loop starts at the first
// light some lane still needs, so every dispatch moves on. Returns true where
// the budget suspended it (r then waits to resume at the next light).
bool shadeLights(inout SlotState state, inout Ray r, vec3 weight, Hit h, bool shading, inout uint shadowRays) {
#ifndef SNELL_RAY_QUERY
    // Every lane, shading or not, walks the subgroup's shadow rays.
    if (HAS_LIGHTS && SHARE_SHADOW_RAYS && USE_BVH && SHADOWS && LOOP_BUDGET == 0u && gl_SubgroupSize <= 16u) {
        shadeLightsShared(state, r, weight, h, shading, shadowRays);
        return false;
    }
#endif
    if (!HAS_LIGHTS || !(shading || LOOP_BUDGET != 0u)) return false;
    rvec3 v = -r.dir;
    uint firstLight = LOOP_BUDGET != 0u ? subgroupMin(shading ? max(r.resumeShading, 1u) - 1u : frame.lightCount) : 0u;
    for (uint j = firstLight; j < frame.lightCount; ++j) {
        // At least one light a dispatch, whatever the hit cost: progress.
        if (j > firstLight && loopBudgetSpent()) {
            if (shading) {
                r.resumeShading = max(r.resumeShading, j + 1u);
                r.weight = weight;
            }
            return true;
        }
        tick(2u);  // this light, and the occlusion loop should no lane enter it
        if (shading && j + 1u >= r.resumeShading) state.sum.rgb += weighted(weight, shadeLight(j, h, v, shadowRays));
    }
    return false;
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
    // With a loop budget every lane stays in this loop until the subgroup
    // leaves it together, so the subgroup operations below see all lanes.
    while (true) {
        if (LOOP_BUDGET != 0u) {
            if (subgroupAll(done)) break;
            if (loopBudgetSpent()) {
                suspended = true;
                break;
            }
        } else if (done) {
            break;
        }
        // This pass, and ahead the pass that ends each loop the pass reaches
        // (loop_budget.glsl): the closest-hit walk, the lights' loop and the
        // occlusion walk in it, takePixel's three (endStep).
        tick(2u + (HAS_LIGHTS ? 2u : 0u) + (HELPS ? 3u : 0u));
        // Asked to stop (Ctrl-C, SIGTERM) while the dispatch runs: this
        // invocation drops its work and the host discards the tile. Read every
        // 256 passes, so even a pixel whose tree never ends is left promptly.
        if (!done && (++passes & 255u) == 0u && atomicAdd(counters[SNELL_COUNTER_CANCEL], 0u) != 0u) {
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
        if (!done && !hasRay) hasRay = nextRay(slot, state, pixel, ray);
        if (COUNT_LANES) countLanes(hasRay, traceSlots, traceBusy);
        // Trace the ray in hand: closest hit, local term, children.
        vec3 weight = vec3(0.0);
        Hit h;
        bool shading = hasRay && traceRay(slot, state, ray, cutOff, weight, h, deepest);
        hasRay = shading;
        // 3. Lights (suspending shading part-way where the loop budget is spent).
        if (shadeLights(state, ray, weight, h, shading, shadowRays)) {
            suspended = true;
            break;
        }
        if (shading) hasRay = spawnChildren(slot, state, ray, weight, h, cutOff);
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
