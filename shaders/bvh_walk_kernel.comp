// The BVH walk's floor: what the renderer's walk costs with nothing around
// it. Each invocation takes one pixel's camera ray (SPEC §3, the pixel's
// centre) through the scene's BVH to its closest hit (SPEC §4.1) and, from
// there, a shadow ray to each light on the lit side (SPEC §4.3), with the
// renderer's own walk (bvh_walk.glsl) and intersection (intersect.glsl); no
// shading, no ray tree, no pixel scheduling. `snell bench` sets its time
// beside the renderer's at --depth 0 on the same BVH scene, which casts the
// same rays (docs/log/bvh-walk.md, "The walk's floor").
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "shared_layout.h"
#include "kernel_layout.h"
#include "intersect.glsl"
#include "wide_words.glsl"

layout(local_size_x = SNELL_KERNEL_GROUP_SIZE) in;
layout(constant_id = 0) const uint BVH_DEPTH = 1u;
layout(constant_id = 1) const bool STACK_IN_REGISTERS = false;

layout(set = 0, binding = 0, std430) readonly buffer FrameBuffer { FrameParams frame; };
layout(set = 0, binding = 1, std430) readonly buffer SphereBuffer { Sphere spheres[]; };
layout(set = 0, binding = 2, std430) readonly buffer EllipsoidBuffer { Ellipsoid ellipsoids[]; };
layout(set = 0, binding = 3, std430) readonly buffer LightBuffer { Light lights[]; };
// Per pixel: the sphere hit (or NONE), the shadow rays cast, those blocked.
layout(set = 0, binding = 4, std430) writeonly buffer ResultBuffer { uvec4 results[]; };

const uint NONE = 0xffffffffu;

// The nodes through their device address as 64-bit halves, as the renderer
// reads them on lavapipe (shared_layout.h): the fastest of its ways there.
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BvhWords { u64vec2 words[]; };
uvec4 bvhWord(int i) { return fromHalves(BvhWords(uvec2(frame.bvhAddressLow, frame.bvhAddressHigh)).words[i]); }

mat4 ellipsoidMatrix(uint e) {
    Ellipsoid m = ellipsoids[e];
    return transpose(mat4(m.row0, m.row1, m.row2, vec4(0.0, 0.0, 0.0, 1.0)));
}

real intersectSphere(uint index, vec3 origin, float originLength, vec3 dir, uint fromSphere, uint start) {
    uint mode = index == fromSphere ? start : ELSEWHERE;
    Sphere s = spheres[index];
    if (s.anchorRadius.w < 0.0)
        return intersectEllipsoid(ellipsoidMatrix(uint(-s.anchorRadius.w) - 1u), s.normal.w, origin, originLength,
                                  dir, mode);
    return intersectTrueSphere(s.anchorRadius, s.normal, origin, originLength, dir, mode);
}
// The walk's floor keeps no margins (margins.glsl).
void offer(real t, uint i, inout real tHit, inout uint hit) {
    if (t < tHit) {
        tHit = t;
        hit = i;
    }
}
real cullSlack() { return 0.0; }

#include "bvh_walk.glsl"

uint walk(vec3 origin, vec3 dir, uint fromSphere, uint start, bool anyHit, inout float tHit) {
    vec3 inverseDir = safeInverse(dir);
    float originLength = length(origin);
    uint hit = NONE;
    uint entry = 0u;
    uint depth = 0u;
    bool walking = true;
    while (walking)
        walkPass(entry, depth, walking, tHit, hit, origin, originLength, dir, inverseDir, fromSphere, start, anyHit);
    return hit;
}

void main() {
    uint pixel = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * SNELL_KERNEL_GROUP_SIZE +
                 gl_LocalInvocationID.x;
    if (pixel >= frame.imageWidth * frame.imageHeight) return;
    vec2 q = vec2(pixel % frame.imageWidth, pixel / frame.imageWidth) + 0.5;
    vec3 dir = normalize(frame.cornerDir.xyz + q.x * frame.pixelRight.xyz + q.y * frame.pixelDown.xyz);
    vec3 origin = frame.primaryStart.xyz + frame.primaryStart.w * dir;
    float t = NO_HIT;
    uint hit = walk(origin, dir, NONE, ELSEWHERE, false, t);
    uint shadowRays = 0u;
    uint blocked = 0u;
    if (hit != NONE) {
        // The hit's outward normal, as the renderer's findHit has it.
        vec3 point = origin + t * dir;
        Sphere s = spheres[hit];
        vec3 outward;
        if (s.anchorRadius.w < 0.0) {
            mat4 objectFromWorld = ellipsoidMatrix(uint(-s.anchorRadius.w) - 1u);
            vec3 p = (objectFromWorld * vec4(origin, 1.0)).xyz + t * (mat3(objectFromWorld) * dir);
            outward = normalize(transpose(mat3(objectFromWorld)) * p);
        } else {
            outward = normalize(origin - s.anchorRadius.xyz + t * dir + s.anchorRadius.w * s.normal.xyz);
        }
        bool fromOutside = dot(dir, outward) < 0.0;
        vec3 normal = fromOutside ? outward : -outward;
        for (uint j = 0u; j < frame.lightCount; ++j) {
            vec3 l = lights[j].position.xyz - point;
            float distance = length(l);
            l *= 1.0 / distance;
            if (!(dot(normal, l) > 0.0)) continue;
            ++shadowRays;
            float reach = distance;
            if (walk(point, l, hit, fromOutside ? LEAVING : ENTERING, true, reach) != NONE) ++blocked;
        }
    }
    results[pixel] = uvec4(hit, shadowRays, blocked, 0u);
}
