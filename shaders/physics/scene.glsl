// The scene as the kernel reads it (SPEC §2, laid out by shared_layout.h):
// spheres, their materials, the lights and the frame, in the shader's
// precision (precision.glsl). Accessors only: no scheduling.
#ifndef SNELL_PHYSICS_SCENE_GLSL
#define SNELL_PHYSICS_SCENE_GLSL

// What this scene uses (host/gpu/KernelPolicy.cpp sets them): code for a
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
layout(constant_id = SNELL_SPEC_BVH_WORDS) const bool BVH_WORDS = false;
layout(constant_id = SNELL_SPEC_STACK_IN_REGISTERS) const bool STACK_IN_REGISTERS = false;

layout(set = 0, binding = SNELL_BINDING_FRAME, std140) uniform FrameBlock { FrameParams frame; };
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

// A small scene's spheres (SPHERE_COUNT > 0), read once per dispatch
// (preloadSpheres), so that each unrolled test reads registers.
rvec4 preloadedAnchor[SNELL_MAX_UNROLLED_SPHERES];
rvec4 preloadedNormal[SNELL_MAX_UNROLLED_SPHERES];
// An unrolled ellipsoid's map (ELLIPSOID_MASK), read once per dispatch: its
// three texels fetched at every test (on lavapipe a call of ~64 instructions
// each, whatever the index) cost bench/simple a quarter of its dispatch.
rmat4 preloadedEllipsoid[SNELL_MAX_UNROLLED_SPHERES];
void preloadSpheres() {
    [[unroll]] for (uint i = 0u; i < SPHERE_COUNT; ++i) {
        preloadedAnchor[i] = sphereAnchor(i);
        preloadedNormal[i] = sphereNormal(i);
        if (HAS_ELLIPSOIDS && ((ELLIPSOID_MASK >> i) & 1u) != 0u)
            preloadedEllipsoid[i] = ellipsoidMatrix(uint(-preloadedAnchor[i].w) - 1u);
    }
}

#endif
