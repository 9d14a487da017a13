// snell's renderer: one pixel per invocation, SPEC §3–§5 in float32, or in
// double when compiled with SNELL_FP64 (precision.glsl; --precision fp64).
// The path of one ray: camera (main) -> trace (explicit stack) -> closestHit /
// intersectSphere -> shade (local Phong term, shadow rays) -> children pushed
// on the stack. Its double-precision twin is host/reference/CpuRenderer.cpp;
// the intersection maths is explained in host/reference/Intersect.h.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "shared_layout.h"
#include "intersect.glsl"

layout(local_size_x = SNELL_WORKGROUP_SIZE_X, local_size_y = SNELL_WORKGROUP_SIZE_Y) in;

// What this scene uses (host/gpu/ComputeRenderer.cpp sets them): code for a
// feature the scene lacks is dead and removed when the pipeline is compiled.
layout(constant_id = SNELL_SPEC_USE_BVH) const bool USE_BVH = false;
layout(constant_id = SNELL_SPEC_HAS_ELLIPSOIDS) const bool HAS_ELLIPSOIDS = true;
layout(constant_id = SNELL_SPEC_HAS_REFRACTION) const bool HAS_REFRACTION = true;
layout(constant_id = SNELL_SPEC_HAS_REFLECTION) const bool HAS_REFLECTION = true;
layout(constant_id = SNELL_SPEC_HAS_LIGHTS) const bool HAS_LIGHTS = true;
layout(constant_id = SNELL_SPEC_COUNT_RAYS) const bool COUNT_RAYS = false;
layout(constant_id = SNELL_SPEC_MAX_MEDIA) const int MAX_MEDIA = 1;
layout(constant_id = SNELL_SPEC_RAY_STACK) const int RAY_STACK = 8;
layout(constant_id = SNELL_SPEC_AMPLIFYING) const bool AMPLIFYING = false;
// Loop iterations a subgroup may spend in one dispatch before its pixels
// suspend; 0: no limit (drivers without llvmpipe's loop limiter).
layout(constant_id = SNELL_SPEC_LOOP_BUDGET) const uint LOOP_BUDGET = 0u;
// Off (a preview inspection switch): no shadow rays, every light is seen.
layout(constant_id = SNELL_SPEC_SHADOWS) const bool SHADOWS = true;

layout(set = 0, binding = SNELL_BINDING_OUTPUT_IMAGE, rgba32f) uniform writeonly image2D outputImage;
layout(set = 0, binding = SNELL_BINDING_FRAME, std140) uniform FrameBlock { FrameParams frame; };
layout(set = 0, binding = SNELL_BINDING_SPHERES, std430) readonly buffer SphereBlock { Sphere spheres[]; };
layout(set = 0, binding = SNELL_BINDING_ELLIPSOIDS, std430) readonly buffer EllipsoidBlock { Ellipsoid ellipsoids[]; };
layout(set = 0, binding = SNELL_BINDING_MATERIALS, std430) readonly buffer MaterialBlock { Material materials[]; };
layout(set = 0, binding = SNELL_BINDING_LIGHTS, std430) readonly buffer LightBlock { Light lights[]; };
layout(set = 0, binding = SNELL_BINDING_BVH, std430) readonly buffer BvhBlock { BvhNode nodes[]; };
layout(set = 0, binding = SNELL_BINDING_COUNTERS, std430) buffer CounterBlock { uint counters[]; };
layout(set = 0, binding = SNELL_BINDING_PIXEL_STATES, std430) buffer PixelStateBlock { PixelState pixelStates[]; };
layout(set = 0, binding = SNELL_BINDING_RAY_STACK, std430) buffer RayStackBlock { PendingRay rayStack[]; };
layout(set = 0, binding = SNELL_BINDING_MEDIA_STACK, std430) buffer MediaStackBlock { uint mediaStack[]; };
layout(push_constant) uniform TileBlock { TileParams tile; };

// Scene values as the shader computes with them. In fp64 a value is its float
// pair hi + lo: the low parts live in twin buffers of the same layout.
#ifdef SNELL_FP64
layout(set = 0, binding = SNELL_BINDING_FRAME_LOW, std140) uniform FrameLowBlock { FrameParams frameLow; };
layout(set = 0, binding = SNELL_BINDING_SPHERES_LOW, std430) readonly buffer SphereLowBlock { Sphere sphereLows[]; };
layout(set = 0, binding = SNELL_BINDING_ELLIPSOIDS_LOW, std430) readonly buffer EllipsoidLowBlock {
    Ellipsoid ellipsoidLows[];
};
layout(set = 0, binding = SNELL_BINDING_LIGHTS_LOW, std430) readonly buffer LightLowBlock { Light lightLows[]; };
layout(set = 0, binding = SNELL_BINDING_RAY_STACK_LOW, std430) buffer RayStackLowBlock { PendingRay rayStackLow[]; };
#define WIDE(hi, lo) (dvec4(hi) + dvec4(lo))
#define WIDE_MATRIX(hi, lo) (dmat4(hi) + dmat4(lo))
#else
#define WIDE(hi, lo) (hi)
#define WIDE_MATRIX(hi, lo) (hi)
#endif
rvec4 sphereAnchor(uint i) { return WIDE(spheres[i].anchorRadius, sphereLows[i].anchorRadius); }
rvec3 sphereNormal(uint i) { return WIDE(spheres[i].normal, sphereLows[i].normal).xyz; }
rmat4 ellipsoidMatrix(uint e) { return WIDE_MATRIX(ellipsoids[e].objectFromWorld, ellipsoidLows[e].objectFromWorld); }
rvec3 lightPosition(uint j) { return WIDE(lights[j].position, lightLows[j].position).xyz; }

const uint NONE = 0xffffffffu;

uint countedRays[SNELL_RAY_COUNTER_COUNT];

// Loop iterations this subgroup has run in this dispatch, as llvmpipe's loop
// limiter counts them: every pass of a loop with some lane active, plus one
// final pass per loop entry. One lane of the active ones counts each pass, so
// the subgroup's sum is the count. Compiled out when LOOP_BUDGET is 0.
uint loopTicks = 0u;
void tick() {
    if (LOOP_BUDGET != 0u && subgroupElect()) loopTicks++;
}

// ---------------------------------------------------------------------------
// Intersection: the maths is in intersect.glsl (shared with the test kernel);
// here the sphere is fetched and the ray's relation to it decided.

real intersectSphere(uint index, rvec3 origin, rvec3 dir, uint fromSphere, uint start) {
    uint mode = index == fromSphere ? start : ELSEWHERE;
    if (mode == LEAVING) return NO_HIT;
    uint ellipsoid = spheres[index].ellipsoid;
    if (HAS_ELLIPSOIDS && ellipsoid != SNELL_NOT_ELLIPSOID)
        return intersectEllipsoid(ellipsoidMatrix(ellipsoid), origin, dir, mode);
    return intersectTrueSphere(sphereAnchor(index), sphereNormal(index), origin, dir, mode);
}

// Slab test against a node's box (stored rounded outwards), within [0, tMax].
bool hitsBox(uint node, rvec3 origin, rvec3 inverseDir, real tMax) {
    rvec3 t0 = (rvec3(nodes[node].lower.xyz) - origin) * inverseDir;
    rvec3 t1 = (rvec3(nodes[node].upper.xyz) - origin) * inverseDir;
    rvec3 tNear = min(t0, t1);
    rvec3 tFar = max(t0, t1);
    real enter = max(max(tNear.x, tNear.y), max(tNear.z, 0.0));
    // Ize, "Robust BVH Ray Traversal" (JCGT 2013): widen the exit distance so
    // rounding never culls a box the ray touches.
    real leave = min(min(tFar.x, tFar.y), min(tFar.z, tMax)) * (1.0 + 8.0 * UNIT_ROUNDOFF);
    return enter <= leave;
}

rvec3 safeInverse(rvec3 d) {
    const real tiny = 1e-30;
    return 1.0 / mix(d, rvec3(tiny) * sign(d + rvec3(1e-38)), lessThan(abs(d), rvec3(tiny)));
}

// SPEC §4.1: the closest hit with t > 0; returns the sphere index or NONE.
// The BVH is walked without a stack (nodes in depth-first order with skip
// links, see shared_layout.h): no per-invocation array, which matters on
// lavapipe, where dynamically indexed private arrays go to scratch memory.
uint closestHit(rvec3 origin, rvec3 dir, uint fromSphere, uint start, out real tHit) {
    tHit = NO_HIT;
    uint hit = NONE;
    if (!USE_BVH) {
        tick();
        for (uint i = 0u; i < frame.sphereCount; ++i) {
            tick();
            real t = intersectSphere(i, origin, dir, fromSphere, start);
            if (t < tHit) { tHit = t; hit = i; }
        }
        return hit;
    }
    rvec3 inverseDir = safeInverse(dir);
    uint node = 0u;
    tick();
    while (node < frame.bvhNodeCount) {
        tick();
        if (!hitsBox(node, origin, inverseDir, tHit)) {
            node = nodes[node].skip;
            continue;
        }
        uint count = nodes[node].count;
        if (count == 0u) {
            node++;
            continue;
        }
        uint first = nodes[node].first;
        tick();
        for (uint i = first; i < first + count; ++i) {
            tick();
            real t = intersectSphere(i, origin, dir, fromSphere, start);
            if (t < tHit) { tHit = t; hit = i; }
        }
        node = nodes[node].skip;
    }
    return hit;
}

// SPEC §4.3 visibility: does any surface cross the open segment (0, distance)?
bool occluded(rvec3 origin, rvec3 dir, real distance, uint fromSphere, uint start) {
    bool blocked = false;
    if (!USE_BVH) {
        tick();
        for (uint i = 0u; i < frame.sphereCount && !blocked; ++i) {
            tick();
            blocked = intersectSphere(i, origin, dir, fromSphere, start) < distance;
        }
        return blocked;
    }
    rvec3 inverseDir = safeInverse(dir);
    uint node = 0u;
    tick();
    while (node < frame.bvhNodeCount && !blocked) {
        tick();
        if (!hitsBox(node, origin, inverseDir, distance)) {
            node = nodes[node].skip;
            continue;
        }
        uint count = nodes[node].count;
        if (count == 0u) {
            node++;
            continue;
        }
        uint first = nodes[node].first;
        tick();
        for (uint i = first; i < first + count && !blocked; ++i) {
            tick();
            blocked = intersectSphere(i, origin, dir, fromSphere, start) < distance;
        }
        node = nodes[node].skip;
    }
    return blocked;
}

// ---------------------------------------------------------------------------
// The ray tree (SPEC §4), depth first on an explicit stack kept per pixel in
// rayStack/mediaStack, so a pixel can suspend between dispatches. Each pending
// ray carries its weight, depth, the sphere it starts on, whether it heads into
// that sphere, and its medium stack (innermost last).

bool worthTracing(vec3 w) {
    float m = max(w.x, max(w.y, w.z));
    return m > 0.0 && m >= frame.ambient.w;
}

// Local Phong term with binary shadows (SPEC §4.3) at x with shading normal n.
vec3 shade(Material m, rvec3 x, rvec3 n, rvec3 v, uint hitSphere, bool fromOutside) {
    vec3 local = frame.ambient.rgb * m.kd.rgb;
    if (HAS_LIGHTS) {
        // A shadow ray towards N's side enters the hit sphere only when N = −No.
        uint start = fromOutside ? LEAVING : ENTERING;
        tick();
        for (uint j = 0u; j < frame.lightCount; ++j) {
            tick();
            rvec3 l = lightPosition(j) - x;
            real distance = length(l);
            l /= distance;
            float nl = float(dot(n, l));
            if (nl > 0.0) {
                if (COUNT_RAYS && SHADOWS) countedRays[SNELL_COUNTER_SHADOW]++;
                if (!SHADOWS || !occluded(x, l, distance, hitSphere, start)) {
                    float rv = float(dot(2.0 * dot(n, l) * n - l, v));
                    float specular = rv > 0.0 ? pow(rv, m.kd.w) : 0.0;
                    local += lights[j].colour.rgb * (m.kd.rgb * nl + m.ks.rgb * specular);
                }
            }
        }
    }
    return local;
}

// The ray being traced lives in registers; only a deferred child (the
// reflected one, when a ray also refracts) goes to the pixel's stack in
// device memory, and so does the current ray when the pixel suspends.
struct Ray {
    rvec3 origin;
    rvec3 dir;
    vec3 weight;      // product of the ks/kt factors along its path
    uint depth;
    uint fromSphere;  // the sphere whose surface it starts on
    bool inward;      // it heads into that sphere
    uint mediaCount;  // its medium stack is `media`, innermost last
};
uint media[MAX_MEDIA];

float etaOfSphere(uint sphere) { return materials[spheres[sphere].material].kt.w; }

void pushRay(uint pixel, inout PixelState state, Ray r) {
    uint slot = pixel * uint(RAY_STACK) + state.pending;
    vec4 origin = vec4(r.origin, 0.0);
    vec4 dir = vec4(r.dir, 0.0);
    rayStack[slot] = PendingRay(origin, dir, vec4(r.weight, 0.0), r.depth, r.fromSphere, r.inward ? 1u : 0u,
                                r.mediaCount);
#ifdef SNELL_FP64
    rayStackLow[slot].origin = vec4(r.origin - dvec3(origin.xyz), 0.0);
    rayStackLow[slot].direction = vec4(r.dir - dvec3(dir.xyz), 0.0);
#endif
    tick();
    for (uint k = 0u; k < r.mediaCount; ++k) {
        tick();
        mediaStack[slot * uint(MAX_MEDIA) + k] = media[k];
    }
    state.pending++;
}

Ray popRay(uint pixel, inout PixelState state) {
    state.pending--;
    uint slot = pixel * uint(RAY_STACK) + state.pending;
    PendingRay p = rayStack[slot];
    tick();
    for (uint k = 0u; k < p.mediaCount; ++k) {
        tick();
        media[k] = mediaStack[slot * uint(MAX_MEDIA) + k];
    }
    return Ray(WIDE(p.origin, rayStackLow[slot].origin).xyz, WIDE(p.direction, rayStackLow[slot].direction).xyz,
               p.weight.rgb, p.depth, p.fromSphere, p.inward != 0u, p.mediaCount);
}

// Trace ray r: closest hit, local term, children. On return r is the child
// to trace next (hasRay), the other child having been pushed on the stack;
// refraction is traced first, as in the CPU reference.
void traceRay(uint pixel, inout PixelState state, inout Ray r, out bool hasRay, float saturation) {
    hasRay = false;
    vec3 weight = r.weight;
    if (AMPLIFYING) weight = mix(weight, vec3(0.0), greaterThanEqual(state.sum.rgb, vec3(saturation)));
    if (!worthTracing(weight)) return;
    rvec3 o = r.origin;
    rvec3 d = r.dir;

    // 1. Closest hit.
    real t;
    uint hitSphere = closestHit(o, d, r.fromSphere, r.inward ? ENTERING : LEAVING, t);
    if (hitSphere == NONE) {
        state.sum.rgb += weight * frame.background.rgb;
        return;
    }
    uint ellipsoid = spheres[hitSphere].ellipsoid;
    Material m = materials[spheres[hitSphere].material];

    // 2. Hit point o + t d, not re-projected onto the surface: re-projecting
    // (centre + r n̂, or normalising the object-space point) rounds at the
    // scale of the centre or of the largest semi-axis, which for a big floor
    // sphere near the camera is 100× the error of o + t d. Self-intersection
    // needs no point exactly on the surface (see intersectSphere).
    rvec3 x = o + t * d;
    rvec3 outward;
    if (HAS_ELLIPSOIDS && ellipsoid != SNELL_NOT_ELLIPSOID) {
        rmat4 objectFromWorld = ellipsoidMatrix(ellipsoid);
        rvec3 p = (objectFromWorld * rvec4(o, 1.0)).xyz + t * (rmat3(objectFromWorld) * d);
        outward = normalize(transpose(rmat3(objectFromWorld)) * p);
    } else {
        rvec4 anchor = sphereAnchor(hitSphere);
        outward = normalize(o - anchor.xyz + t * d + anchor.w * sphereNormal(hitSphere));
    }
    bool fromOutside = dot(d, outward) < 0.0;
    rvec3 n = fromOutside ? outward : -outward;

    // 3. Local term.
    state.sum.rgb += weight * shade(m, x, n, -d, hitSphere, fromOutside);
    if (r.depth >= frame.maxDepth) return;

    // 4. Reflection (keeps the medium stack) and 5. refraction.
    vec3 reflectedWeight = HAS_REFLECTION ? weight * m.ks.rgb : vec3(0.0);
    bool refracts = false;
    rvec3 refracted = rvec3(0.0);
    vec3 transmittedWeight = vec3(0.0);
    uint removeAt = r.mediaCount;  // leaving: where this sphere is in the stack
    if (HAS_REFRACTION && max(m.kt.r, max(m.kt.g, m.kt.b)) > 0.0) {
        transmittedWeight = weight * m.kt.rgb;
        real etaI, etaT;
        if (fromOutside) {
            // Entering: from the current medium into this sphere.
            etaI = r.mediaCount == 0u ? frame.background.w : etaOfSphere(media[r.mediaCount - 1u]);
            etaT = m.kt.w;
        } else {
            // Leaving: into the medium that remains once this sphere is removed
            // from the stack (its innermost occurrence; none: nothing removed).
            etaI = m.kt.w;
            tick();
            for (uint k = 0u; k < r.mediaCount; ++k) {
                tick();
                if (media[k] == hitSphere) removeAt = k;
            }
            uint innermost = r.mediaCount;  // the innermost one that stays
            tick();
            for (uint k = 0u; k < r.mediaCount; ++k) {
                tick();
                if (k != removeAt) innermost = k;
            }
            etaT = innermost == r.mediaCount ? frame.background.w : etaOfSphere(media[innermost]);
        }
        // Snell's law, SPEC §4.5.
        real eta = etaI / etaT;
        real c = -dot(n, d);
        real k = 1.0 - eta * eta * (1.0 - c * c);
        if (k < 0.0) {
            // Total internal reflection is the reflected ray in the same medium:
            // one ray carries both weights.
            reflectedWeight += transmittedWeight;
        } else if (worthTracing(transmittedWeight)) {
            refracts = true;
            refracted = normalize(eta * d + (eta * c - sqrt(k)) * n);
        }
    }
    bool reflects = (HAS_REFLECTION || HAS_REFRACTION) && worthTracing(reflectedWeight);
    Ray reflectedRay = Ray(x, d - 2.0 * dot(d, n) * n, reflectedWeight, r.depth + 1u, hitSphere, !fromOutside,
                           r.mediaCount);
    if (reflects) {
        if (COUNT_RAYS) countedRays[SNELL_COUNTER_REFLECTED]++;
        if (!refracts) {
            r = reflectedRay;
            hasRay = true;
            return;
        }
        pushRay(pixel, state, reflectedRay);  // with the parent's media, still current
    }
    if (refracts) {
        if (COUNT_RAYS) countedRays[SNELL_COUNTER_REFRACTED]++;
        uint count = r.mediaCount;
        if (fromOutside) {
            if (count == uint(MAX_MEDIA)) {  // deeper than the scene can nest: forget the outermost
                tick();
                for (uint k = 0u; k + 1u < count; ++k) {
                    tick();
                    media[k] = media[k + 1u];
                }
                count--;
            }
            media[count] = hitSphere;
            count++;
        } else if (removeAt < count) {
            tick();
            for (uint k = removeAt; k + 1u < count; ++k) {
                tick();
                media[k] = media[k + 1u];
            }
            count--;
        }
        r = Ray(x, refracted, transmittedWeight, r.depth + 1u, hitSphere, fromOutside, count);
        hasRay = true;
    }
}

void main() {
    uvec2 local = gl_GlobalInvocationID.xy;
    bool inTile = local.x < tile.width && local.y < tile.height;
    uint pixel = local.y * tile.width + local.x;
    for (int k = 0; k < SNELL_RAY_COUNTER_COUNT; ++k) countedRays[k] = 0u;

    PixelState state;
    bool done = true;
    if (inTile) {
        state = pixelStates[pixel];
        done = state.done != 0u;
    }
    // SPEC §3: s×s rays through (i + (a+½)/s, j + (b+½)/s); mean, then clamp on output.
    uint s = frame.supersample;
    uint samples = frame.sampleCount;
    float saturation = AMPLIFYING ? float(samples) : 3.0e38;
    uvec2 imagePixel = local + uvec2(tile.originX, tile.originY);

    Ray ray;
    bool hasRay = false;
    // Every lane stays in this loop until the subgroup leaves it together, so
    // the subgroup operations below see all lanes.
    while (true) {
        if (LOOP_BUDGET != 0u) {
            if (subgroupAll(done) || subgroupAdd(loopTicks) >= LOOP_BUDGET) break;
        } else if (done) {
            break;
        }
        tick();
        if (!done) {
            if (!hasRay && state.pending > 0u) {
                ray = popRay(pixel, state);
                hasRay = true;
            }
            if (!hasRay) {
                if (state.started == samples) {
                    done = true;
                } else {
                    // Camera: the next primary ray of this pixel.
                    uint k = frame.firstSample + state.started;
                    uvec2 ab = uvec2(k % s, k / s);
                    rvec2 p = rvec2(imagePixel) + (rvec2(ab) + 0.5) / real(s);
                    rvec3 corner = WIDE(frame.cornerDir, frameLow.cornerDir).xyz;
                    rvec3 right = WIDE(frame.pixelRight, frameLow.pixelRight).xyz;
                    rvec3 down = WIDE(frame.pixelDown, frameLow.pixelDown).xyz;
                    rvec3 dir = normalize(corner + p.x * right + p.y * down);
                    // It starts at distance D along its way, before any geometry.
                    rvec4 primaryStart = WIDE(frame.primaryStart, frameLow.primaryStart);
                    rvec3 start = primaryStart.xyz + primaryStart.w * dir;
                    ray = Ray(start, dir, vec3(1.0), 0u, NONE, false, 0u);
                    hasRay = true;
                    state.started++;
                    if (COUNT_RAYS) countedRays[SNELL_COUNTER_PRIMARY]++;
                }
            }
            if (hasRay) traceRay(pixel, state, ray, hasRay, saturation);
        }
    }

    if (inTile) {
        // Suspending: the ray in hand waits on the stack for the next dispatch.
        if (hasRay) pushRay(pixel, state, ray);
        state.done = done ? 1u : 0u;
        pixelStates[pixel] = state;
        if (done) imageStore(outputImage, ivec2(local), vec4(state.sum.rgb / float(samples), 1.0));
        else atomicAdd(counters[SNELL_COUNTER_UNFINISHED], 1u);
    }
    if (COUNT_RAYS) {
        for (int k = 0; k < SNELL_RAY_COUNTER_COUNT; ++k)
            if (countedRays[k] != 0u) atomicAdd(counters[k], countedRays[k]);
    }
    // Past the driver's limit some loop may have been cut short: say so.
    if (LOOP_BUDGET != 0u) {
        uint spent = subgroupAdd(loopTicks);  // all lanes take part
        if (subgroupElect() && spent >= SNELL_DRIVER_LOOP_LIMIT) atomicAdd(counters[SNELL_COUNTER_LOOP_LIMIT], 1u);
    }
}
