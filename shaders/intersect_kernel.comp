// Test kernel: the renderer's float intersector (intersect.glsl) applied to a
// list of cases, one per invocation; t (or the no-hit value) per case.
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
    float t = c.kind == SNELL_CASE_ELLIPSOID
                  ? intersectEllipsoid(c.objectFromWorld, c.origin.xyz, c.direction.xyz, c.mode)
                  : intersectTrueSphere(c.anchorRadius, c.normal.xyz, c.origin.xyz, c.direction.xyz, c.mode);
    results[i] = vec4(t, 0.0, 0.0, 0.0);
}
