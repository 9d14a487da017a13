// Test kernel: the renderer's intersector (intersect.glsl, float32 or, with
// SNELL_FP64, double) applied to a list of cases, one per invocation; t (or the
// no-hit value) per case, as the float pair hi + lo.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared_layout.h"
#include "kernel_layout.h"
#include "intersect.glsl"

layout(local_size_x = SNELL_KERNEL_GROUP_SIZE) in;
layout(set = 0, binding = 0, std430) readonly buffer CaseBlock { IntersectCase cases[]; };
layout(set = 0, binding = 1, std430) writeonly buffer ResultBlock { vec4 results[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= cases[0].count) return;
    IntersectCase c = cases[i];
#ifdef SNELL_FP64
    dvec3 origin = dvec3(c.origin.xyz) + dvec3(c.originLow.xyz);
    dvec3 direction = dvec3(c.direction.xyz) + dvec3(c.directionLow.xyz);
    dmat4 objectFromWorld = dmat4(c.objectFromWorld) + dmat4(c.objectFromWorldLow);
    dvec4 anchorRadius = dvec4(c.anchorRadius) + dvec4(c.anchorRadiusLow);
    dvec3 normal = dvec3(c.normal.xyz) + dvec3(c.normalLow.xyz);
#else
    vec3 origin = c.origin.xyz;
    vec3 direction = c.direction.xyz;
    mat4 objectFromWorld = c.objectFromWorld;
    vec4 anchorRadius = c.anchorRadius;
    vec3 normal = c.normal.xyz;
#endif
    // What the renderer prepares once per sphere (|P0|, the matrix norm) and per ray (|o|).
    rmat3 m = rmat3(objectFromWorld);
    real matrixNorm = max(max(abs(m[0].x) + abs(m[1].x) + abs(m[2].x), abs(m[0].y) + abs(m[1].y) + abs(m[2].y)),
                          abs(m[0].z) + abs(m[1].z) + abs(m[2].z));
    real originLength = length(origin);
    real t = c.kind == SNELL_CASE_ELLIPSOID
                 ? intersectEllipsoid(objectFromWorld, matrixNorm, origin, originLength, direction, c.mode)
                 : intersectTrueSphere(anchorRadius, rvec4(normal, length(anchorRadius.xyz)), origin, originLength,
                                       direction, c.mode);
#ifdef SNELL_FP64
    float hi, lo;
    splitDouble(t, hi, lo);
    results[i] = vec4(hi, lo, 0.0, 0.0);
#else
    results[i] = vec4(t, 0.0, 0.0, 0.0);
#endif
}
