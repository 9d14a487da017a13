// A ray, the surface it hits, and the arithmetic of the weights it carries
// (SPEC §4): the values the physics passes around. No scheduling.
#ifndef SNELL_PHYSICS_RAY_GLSL
#define SNELL_PHYSICS_RAY_GLSL

const uint NONE = 0xffffffffu;

layout(constant_id = SNELL_SPEC_MAX_MEDIA) const int MAX_MEDIA = 1;

// weight ⊙ colour, where a weight grown to +inf (an amplifying tree, SPEC §4)
// times 0 is 0, not NaN.
vec3 weighted(vec3 weight, vec3 colour) {
    bvec3 zero = bvec3(uvec3(equal(colour, vec3(0.0))) | uvec3(equal(weight, vec3(0.0))));
    return mix(weight * colour, vec3(0.0), zero);
}
float maxChannel(vec3 c) { return max(c.r, max(c.g, c.b)); }
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
    rvec2 off;        // how far it may be from the exact ray: its origin, its direction (margins.glsl)
    bool covered;     // an undecided ancestor's light already covers its own
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
    real distance;    // t of the hit along the ray
    real pointOff;    // how far the point and the normal may be from the exact ray's
    real normalOff;   // (margins.glsl)
    real rounding;    // the point's own rounding, and how fast the normal turns with it
    real turning;
    real viewTilt;    // how far the ray's direction, V of shading, may be turned from the exact one's
    bool undecided;   // the exact ray may meet another surface, none, or this one from its other side
};

#endif
