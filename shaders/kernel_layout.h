// Structs shared by the intersection test kernel (intersect_kernel.comp) and
// its host side (tests/test_intersect_fuzz.cpp). vec4/mat4/uint members only.
#ifndef SNELL_KERNEL_LAYOUT_H
#define SNELL_KERNEL_LAYOUT_H

#ifdef __cplusplus
#include <cstddef>
#include "shared_layout.h"
namespace snell::gpu {
#endif

#define SNELL_KERNEL_GROUP_SIZE 64
#define SNELL_CASE_TRUE_SPHERE 0u
#define SNELL_CASE_ELLIPSOID 1u

// One ray against one sphere, in the renderer's own representation: floats,
// and for the fp64 kernel the low parts of the float pairs (shared_layout.h).
struct IntersectCase {
    vec4 origin;           // xyz
    vec4 direction;        // xyz, unit
    vec4 anchorRadius;     // true sphere: anchor P0 and radius
    vec4 normal;           // true sphere: n0
    mat4 objectFromWorld;  // ellipsoid
    vec4 originLow;        // the low parts of the above
    vec4 directionLow;
    vec4 anchorRadiusLow;
    vec4 normalLow;
    mat4 objectFromWorldLow;
    uint kind;             // SNELL_CASE_*
    uint mode;             // 0 elsewhere, 1 leaving, 2 entering (intersect.glsl)
    uint count;            // in the first case only: how many cases there are
    uint pad0;
};

// The device's ceiling (the micro-kernel ray_sphere_kernel.comp): one
// ray per invocation against SNELL_CEILING_SPHERES spheres.
#define SNELL_CEILING_SPHERES 64
struct CeilingSphere {
    vec4 centreRadius;     // centre + radius form
    mat4 objectFromWorld;  // inverse-matrix form
};

#ifdef __cplusplus
static_assert(sizeof(CeilingSphere) == 80);
static_assert(sizeof(IntersectCase) == 272 && offsetof(IntersectCase, kind) == 256);
}  // namespace snell::gpu
#endif
#endif
