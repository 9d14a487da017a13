// snell's renderer: one pixel per invocation, SPEC §3–§5 in float32.
// The path of one ray: camera (main) -> trace (explicit stack) -> closestHit /
// intersectSphere -> shade (local Phong term, shadow rays) -> children pushed
// on the stack. Its double-precision twin is host/reference/CpuRenderer.cpp;
// the intersection maths is explained in host/reference/Intersect.h.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared_layout.h"

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

layout(set = 0, binding = SNELL_BINDING_OUTPUT_IMAGE, rgba32f) uniform writeonly image2D outputImage;
layout(set = 0, binding = SNELL_BINDING_FRAME, std140) uniform FrameBlock { FrameParams frame; };
layout(set = 0, binding = SNELL_BINDING_SPHERES, std430) readonly buffer SphereBlock { Sphere spheres[]; };
layout(set = 0, binding = SNELL_BINDING_ELLIPSOIDS, std430) readonly buffer EllipsoidBlock { Ellipsoid ellipsoids[]; };
layout(set = 0, binding = SNELL_BINDING_MATERIALS, std430) readonly buffer MaterialBlock { Material materials[]; };
layout(set = 0, binding = SNELL_BINDING_LIGHTS, std430) readonly buffer LightBlock { Light lights[]; };
layout(set = 0, binding = SNELL_BINDING_BVH, std430) readonly buffer BvhBlock { BvhNode nodes[]; };
layout(set = 0, binding = SNELL_BINDING_COUNTERS, std430) buffer CounterBlock { uint rayCounters[]; };
layout(push_constant) uniform TileBlock { TileParams tile; };

const uint NONE = 0xffffffffu;
const float NO_HIT = 3.0e38;
// How a ray relates to the sphere it starts on (see Intersect.h: StartsOn).
const uint ELSEWHERE = 0u;
const uint LEAVING = 1u;
const uint ENTERING = 2u;

uint countedRays[SNELL_COUNTER_COUNT];

// ---------------------------------------------------------------------------
// Intersection: Haines et al. (Ray Tracing Gems ch. 7) roots; exact chord root
// for a ray entering the sphere it starts on, no hit for one leaving it.

float rootsToHit(float b, float a, float c, float discriminant) {
    // q-form: q = −(b + sign(b)·√Δ); roots c/q and q/a, no cancellation.
    float q = -(b + (b >= 0.0 ? sqrt(discriminant) : -sqrt(discriminant)));
    if (q == 0.0) return NO_HIT;
    float t0 = c / q;
    float t1 = q / a;
    float near = min(t0, t1);
    float far = max(t0, t1);
    return near > 0.0 ? near : (far > 0.0 ? far : NO_HIT);
}

float intersectSphere(uint index, vec3 origin, vec3 dir, uint fromSphere, uint start) {
    uint mode = index == fromSphere ? start : ELSEWHERE;
    if (mode == LEAVING) return NO_HIT;
    Sphere s = spheres[index];
    if (HAS_ELLIPSOIDS && s.ellipsoid != SNELL_NOT_ELLIPSOID) {
        mat4 objectFromWorld = ellipsoids[s.ellipsoid].objectFromWorld;
        vec3 o = (objectFromWorld * vec4(origin, 1.0)).xyz;
        vec3 d = mat3(objectFromWorld) * dir;
        float a = dot(d, d);
        float b = dot(o, d);
        if (mode == ENTERING) {
            float chord = -2.0 * b / a;
            return chord > 0.0 ? chord : NO_HIT;
        }
        vec3 perpendicular = o - (b / a) * d;
        float discriminant = a * (1.0 - dot(perpendicular, perpendicular));
        if (discriminant < 0.0) return NO_HIT;
        return rootsToHit(b, a, dot(o, o) - 1.0, discriminant);
    }
    vec3 f = origin - s.centreRadius.xyz;
    float r = s.centreRadius.w;
    float b = dot(f, dir);
    if (mode == ENTERING) {
        float chord = -2.0 * b;
        return chord > 0.0 ? chord : NO_HIT;
    }
    vec3 perpendicular = f - b * dir;
    float discriminant = r * r - dot(perpendicular, perpendicular);
    if (discriminant < 0.0) return NO_HIT;
    return rootsToHit(b, 1.0, dot(f, f) - r * r, discriminant);
}

// Slab test against a node's box (stored rounded outwards), within [0, tMax].
bool hitsBox(uint node, vec3 origin, vec3 inverseDir, float tMax) {
    vec3 t0 = (nodes[node].lower.xyz - origin) * inverseDir;
    vec3 t1 = (nodes[node].upper.xyz - origin) * inverseDir;
    vec3 tNear = min(t0, t1);
    vec3 tFar = max(t0, t1);
    float enter = max(max(tNear.x, tNear.y), max(tNear.z, 0.0));
    // Ize, "Robust BVH Ray Traversal" (JCGT 2013): widen the exit distance so
    // rounding never culls a box the ray touches.
    float leave = min(min(tFar.x, tFar.y), min(tFar.z, tMax)) * 1.0000004;
    return enter <= leave;
}

// The BVH traversal stack, one per invocation (module scope: see occluded()).
uint bvhStack[SNELL_BVH_STACK];

vec3 safeInverse(vec3 d) {
    const float tiny = 1e-30;
    return 1.0 / mix(d, vec3(tiny) * sign(d + vec3(1e-38)), lessThan(abs(d), vec3(tiny)));
}

// SPEC §4.1: the closest hit with t > 0; returns the sphere index or NONE.
uint closestHit(vec3 origin, vec3 dir, uint fromSphere, uint start, out float tHit) {
    tHit = NO_HIT;
    uint hit = NONE;
    if (!USE_BVH) {
        for (uint i = 0u; i < frame.sphereCount; ++i) {
            float t = intersectSphere(i, origin, dir, fromSphere, start);
            if (t < tHit) { tHit = t; hit = i; }
        }
        return hit;
    }
    vec3 inverseDir = safeInverse(dir);
    int top = 0;
    bvhStack[top++] = 0u;
    while (top > 0) {
        uint node = bvhStack[--top];
        if (!hitsBox(node, origin, inverseDir, tHit)) continue;
        uint first = nodes[node].first;
        uint count = nodes[node].count;
        if (count > 0u) {
            for (uint i = first; i < first + count; ++i) {
                float t = intersectSphere(i, origin, dir, fromSphere, start);
                if (t < tHit) { tHit = t; hit = i; }
            }
        } else if (top + 2 <= SNELL_BVH_STACK) {
            bvhStack[top++] = first + 1u;
            bvhStack[top++] = first;
        }
    }
    return hit;
}

// SPEC §4.3 visibility: does any surface cross the open segment (0, distance)?
// (Loops end through their conditions, not early returns: lavapipe has
// miscompiled a return from inside this traversal for whole SIMD rows.)
bool occluded(vec3 origin, vec3 dir, float distance, uint fromSphere, uint start) {
    bool blocked = false;
    if (!USE_BVH) {
        for (uint i = 0u; i < frame.sphereCount && !blocked; ++i)
            blocked = intersectSphere(i, origin, dir, fromSphere, start) < distance;
        return blocked;
    }
    vec3 inverseDir = safeInverse(dir);
    int top = 0;
    bvhStack[top++] = 0u;
    while (top > 0 && !blocked) {
        uint node = bvhStack[--top];
        if (!hitsBox(node, origin, inverseDir, distance)) continue;
        uint first = nodes[node].first;
        uint count = nodes[node].count;
        if (count > 0u) {
            for (uint i = first; i < first + count && !blocked; ++i)
                blocked = intersectSphere(i, origin, dir, fromSphere, start) < distance;
        } else if (top + 2 <= SNELL_BVH_STACK) {
            bvhStack[top++] = first + 1u;
            bvhStack[top++] = first;
        }
    }
    return blocked;
}

// ---------------------------------------------------------------------------
// The ray tree (SPEC §4), depth first on an explicit stack. Each pending ray
// carries its weight, depth, the sphere it starts on and its medium stack.

vec3 pendingOrigin[RAY_STACK];
vec3 pendingDir[RAY_STACK];
vec3 pendingWeight[RAY_STACK];
uint pendingInfo[RAY_STACK];     // depth | inward << 16
uint pendingFrom[RAY_STACK];
uint pendingMediaCount[RAY_STACK];
uint pendingMedia[RAY_STACK * MAX_MEDIA];
int pendingTop = 0;

uint currentMedia[MAX_MEDIA];
uint currentMediaCount = 0u;

float mediumEta(uint count, uint innermost) {
    return count == 0u ? frame.background.w : materials[spheres[innermost].material].kt.w;
}

void push(vec3 origin, vec3 dir, vec3 weight, uint depth, uint fromSphere, bool inward) {
    if (pendingTop >= RAY_STACK) return;  // cannot happen: RAY_STACK = maxDepth + 1
    int slot = pendingTop++;
    pendingOrigin[slot] = origin;
    pendingDir[slot] = dir;
    pendingWeight[slot] = weight;
    pendingInfo[slot] = depth | (inward ? 0x10000u : 0u);
    pendingFrom[slot] = fromSphere;
    pendingMediaCount[slot] = currentMediaCount;
    for (uint k = 0u; k < currentMediaCount; ++k) pendingMedia[slot * MAX_MEDIA + int(k)] = currentMedia[k];
}

bool worthTracing(vec3 w) {
    float m = max(w.x, max(w.y, w.z));
    return m > 0.0 && m >= frame.ambient.w;
}

// Local Phong term with binary shadows (SPEC §4.3) at x with shading normal n.
vec3 shade(Material m, vec3 x, vec3 n, vec3 v, uint hitSphere, bool fromOutside) {
    vec3 local = frame.ambient.rgb * m.kd.rgb;
    if (!HAS_LIGHTS) return local;
    uint start = fromOutside ? LEAVING : ENTERING;
    for (uint j = 0u; j < frame.lightCount; ++j) {
        vec3 l = lights[j].position.xyz - x;
        float distance = length(l);
        l /= distance;
        float nl = dot(n, l);
        if (!(nl > 0.0)) continue;
        if (COUNT_RAYS) countedRays[SNELL_COUNTER_SHADOW]++;
        if (occluded(x, l, distance, hitSphere, start)) continue;
        float rv = dot(2.0 * nl * n - l, v);
        float specular = rv > 0.0 ? pow(rv, m.kd.w) : 0.0;
        local += lights[j].colour.rgb * (m.kd.rgb * nl + m.ks.rgb * specular);
    }
    return local;
}

void trace(vec3 origin, vec3 dir, inout vec3 pixelSum, float saturation) {
    pendingTop = 0;
    currentMediaCount = 0u;
    push(origin, dir, vec3(1.0), 0u, NONE, false);
    if (COUNT_RAYS) countedRays[SNELL_COUNTER_PRIMARY]++;
    while (pendingTop > 0) {
        int slot = --pendingTop;
        vec3 o = pendingOrigin[slot];
        vec3 d = pendingDir[slot];
        vec3 weight = pendingWeight[slot];
        uint depth = pendingInfo[slot] & 0xffffu;
        bool inward = (pendingInfo[slot] & 0x10000u) != 0u;
        uint fromSphere = pendingFrom[slot];
        if (AMPLIFYING) weight = mix(weight, vec3(0.0), greaterThanEqual(pixelSum, vec3(saturation)));
        if (!worthTracing(weight)) continue;

        // 1. Closest hit.
        float t;
        uint hitSphere = closestHit(o, d, fromSphere, inward ? ENTERING : LEAVING, t);
        if (hitSphere == NONE) {
            pixelSum += weight * frame.background.rgb;
            continue;
        }
        Sphere s = spheres[hitSphere];
        Material m = materials[s.material];

        // 2. Hit point re-projected onto the surface; outward and shading normals.
        vec3 x, outward;
        if (HAS_ELLIPSOIDS && s.ellipsoid != SNELL_NOT_ELLIPSOID) {
            // No re-projection: normalising p would spread the rounding of its
            // largest component (huge for a flat ellipsoid seen edge-on) into
            // the others. o + t d is as exact as float allows.
            mat4 objectFromWorld = ellipsoids[s.ellipsoid].objectFromWorld;
            vec3 p = (objectFromWorld * vec4(o, 1.0)).xyz + t * (mat3(objectFromWorld) * d);
            x = o + t * d;
            outward = normalize(transpose(mat3(objectFromWorld)) * p);
        } else {
            outward = normalize(o - s.centreRadius.xyz + t * d);
            x = s.centreRadius.xyz + s.centreRadius.w * outward;
        }
        bool fromOutside = dot(d, outward) < 0.0;
        vec3 n = fromOutside ? outward : -outward;

        // 3. Local term.
        pixelSum += weight * shade(m, x, n, -d, hitSphere, fromOutside);
        if (depth >= frame.maxDepth) continue;

        // 4–5. Children. The medium stack of this ray becomes current.
        uint mediaCount = pendingMediaCount[slot];
        for (uint k = 0u; k < mediaCount; ++k) currentMedia[k] = pendingMedia[slot * MAX_MEDIA + int(k)];
        currentMediaCount = mediaCount;
        vec3 reflectedWeight = HAS_REFLECTION ? weight * m.ks.rgb : vec3(0.0);
        vec3 reflected = d - 2.0 * dot(d, n) * n;
        if (HAS_REFRACTION && max(m.kt.r, max(m.kt.g, m.kt.b)) > 0.0) {
            vec3 transmittedWeight = weight * m.kt.rgb;
            float etaI, etaT;
            if (fromOutside) {
                etaI = mediumEta(currentMediaCount, currentMediaCount > 0u ? currentMedia[currentMediaCount - 1u] : 0u);
                etaT = m.kt.w;
                if (currentMediaCount == uint(MAX_MEDIA)) {  // deeper than the scene can nest: drop outermost
                    for (int k = 0; k + 1 < MAX_MEDIA; ++k) currentMedia[k] = currentMedia[k + 1];
                    currentMediaCount--;
                }
                currentMedia[currentMediaCount++] = hitSphere;
            } else {
                etaI = m.kt.w;
                for (int k = int(currentMediaCount) - 1; k >= 0; --k) {
                    if (currentMedia[k] == hitSphere) {
                        for (int j = k; j + 1 < int(currentMediaCount); ++j) currentMedia[j] = currentMedia[j + 1];
                        currentMediaCount--;
                        break;
                    }
                }
                etaT = mediumEta(currentMediaCount, currentMediaCount > 0u ? currentMedia[currentMediaCount - 1u] : 0u);
            }
            // Snell's law, SPEC §4.5.
            float eta = etaI / etaT;
            float c = -dot(n, d);
            float k = 1.0 - eta * eta * (1.0 - c * c);
            if (k < 0.0) {
                // Total internal reflection: the reflected ray, same medium.
                reflectedWeight += transmittedWeight;
            } else if (worthTracing(transmittedWeight)) {
                if (COUNT_RAYS) countedRays[SNELL_COUNTER_REFRACTED]++;
                push(x, normalize(eta * d + (eta * c - sqrt(k)) * n), transmittedWeight, depth + 1u,
                     hitSphere, fromOutside);
            }
            // Reflected rays keep the parent's medium stack.
            for (uint j = 0u; j < mediaCount; ++j) currentMedia[j] = pendingMedia[slot * MAX_MEDIA + int(j)];
            currentMediaCount = mediaCount;
        }
        if (HAS_REFLECTION || HAS_REFRACTION) {
            if (worthTracing(reflectedWeight)) {
                if (COUNT_RAYS) countedRays[SNELL_COUNTER_REFLECTED]++;
                push(x, reflected, reflectedWeight, depth + 1u, hitSphere, !fromOutside);
            }
        }
    }
}

void main() {
    uvec2 local = gl_GlobalInvocationID.xy;
    if (local.x >= tile.width || local.y >= tile.height) return;
    uvec2 pixel = local + uvec2(tile.originX, tile.originY);
    for (int k = 0; k < SNELL_COUNTER_COUNT; ++k) countedRays[k] = 0u;

    // SPEC §3: s×s rays through (i + (a+½)/s, j + (b+½)/s); mean, then clamp on output.
    uint s = frame.supersample;
    float samples = float(s * s);
    float saturation = AMPLIFYING ? samples : NO_HIT;
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < s * s; ++k) {
        uint a = k % s;
        uint b = k / s;
        vec2 p = vec2(pixel) + (vec2(a, b) + 0.5) / float(s);
        vec3 dir = normalize(frame.cornerDir.xyz + p.x * frame.pixelRight.xyz + p.y * frame.pixelDown.xyz);
        trace(vec3(0.0), dir, sum, saturation);
    }
    imageStore(outputImage, ivec2(local), vec4(sum / samples, 1.0));
    if (COUNT_RAYS) {
        for (int k = 0; k < SNELL_COUNTER_COUNT; ++k)
            if (countedRays[k] != 0u) atomicAdd(rayCounters[k], countedRays[k]);
    }
}
