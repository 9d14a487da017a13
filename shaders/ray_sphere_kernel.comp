// The device's ray–sphere ceiling: each invocation casts one ray
// against SNELL_CEILING_SPHERES spheres read from a storage buffer and keeps
// the nearest hit: nothing but intersection tests, in the centre + radius
// form (default) or, with SNELL_MATRIX_FORM, the inverse-matrix form the
// renderer uses for ellipsoids. `snell bench` divides tests by time.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared_layout.h"
#include "kernel_layout.h"

layout(local_size_x = SNELL_KERNEL_GROUP_SIZE) in;
layout(set = 0, binding = 0, std430) readonly buffer CeilingSphereBlock { CeilingSphere spheres[]; };
layout(set = 0, binding = 1, std430) writeonly buffer ResultBlock { float nearest[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    // A ray per invocation from near the origin towards -z, spread over the spheres.
    float u = float(i & 1023u) / 1024.0 - 0.5;
    float v = float((i >> 10) & 1023u) / 1024.0 - 0.5;
    vec3 origin = vec3(0.0, 0.0, 1.0);
    vec3 dir = normalize(vec3(u, v, -1.0));
    float best = 3.0e38;
    for (uint k = 0u; k < SNELL_CEILING_SPHERES; ++k) {
#ifdef SNELL_MATRIX_FORM
        mat4 m = spheres[k].objectFromWorld;
        vec3 o = (m * vec4(origin, 1.0)).xyz;
        vec3 d = mat3(m) * dir;
        float a = dot(d, d);
        float b = dot(o, d);
        float c = dot(o, o) - 1.0;
#else
        vec4 s = spheres[k].centreRadius;
        vec3 o = origin - s.xyz;
        float a = 1.0;
        float b = dot(o, dir);
        float c = dot(o, o) - s.w * s.w;
#endif
        float discriminant = b * b - a * c;
        if (discriminant >= 0.0) {
            float t = (-b - sqrt(discriminant)) / a;
            if (t > 0.0 && t < best) best = t;
        }
    }
    nearest[i] = best;
}
