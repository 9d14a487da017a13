// Test kernel: the renderer's intersector (intersect.glsl, float32 or, with
// SNELL_FP64, double) applied to a list of cases, one per invocation; t (or the
// no-hit value) per case, as the float pair hi + lo.
#version 460
#extension GL_GOOGLE_include_directive : require
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
    real t = c.kind == SNELL_CASE_ELLIPSOID ? intersectEllipsoid(objectFromWorld, origin, direction, c.mode)
                                            : intersectTrueSphere(anchorRadius, normal, origin, direction, c.mode);
    float hi = float(t);
    results[i] = vec4(hi, float(t - real(hi)), 0.0, 0.0);
}
