// The one declaration of everything the host and the compute shader share:
// binding numbers, workgroup size, specialization-constant ids and the std430
// structs of the scene buffers. Included by C++ (host/gpu/GpuScene.h) and by
// GLSL (shaders/trace.comp). Members are vec4, mat4 or uint only, so std430 and
// C++ agree without padding rules; host/gpu/GpuScene.h static_asserts sizes.
#ifndef SNELL_SHARED_LAYOUT_H
#define SNELL_SHARED_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace snell::gpu {
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using uint = std::uint32_t;
#define SNELL_CONST constexpr std::uint32_t
#else
#define SNELL_CONST const uint
#endif

// Workgroup: 8x8 pixels, one invocation per pixel.
#define SNELL_WORKGROUP_SIZE_X 8
#define SNELL_WORKGROUP_SIZE_Y 8

// Descriptor set 0.
#define SNELL_BINDING_OUTPUT_IMAGE 0
#define SNELL_BINDING_FRAME 1
#define SNELL_BINDING_SPHERES 2
#define SNELL_BINDING_ELLIPSOIDS 3
#define SNELL_BINDING_MATERIALS 4
#define SNELL_BINDING_LIGHTS 5
#define SNELL_BINDING_BVH 6
#define SNELL_BINDING_COUNTERS 7
#define SNELL_BINDING_PIXEL_STATES 8
#define SNELL_BINDING_RAY_STACK 9
#define SNELL_BINDING_MEDIA_STACK 10
#define SNELL_BINDING_COUNT_FP32 11
// The fp64 shader (--precision fp64) reads scene values as float pairs hi + lo
// (hi = float(v), lo = float(v - hi): 48 bits of the host's double): the hi
// parts are the buffers above, the lo parts twin buffers of the same layout.
#define SNELL_BINDING_FRAME_LOW 11
#define SNELL_BINDING_SPHERES_LOW 12
#define SNELL_BINDING_ELLIPSOIDS_LOW 13
#define SNELL_BINDING_LIGHTS_LOW 14
#define SNELL_BINDING_RAY_STACK_LOW 15
#define SNELL_BINDING_COUNT 16

// Specialization constants: compile only what a scene uses.
#define SNELL_SPEC_USE_BVH 0
#define SNELL_SPEC_HAS_ELLIPSOIDS 1
#define SNELL_SPEC_HAS_REFRACTION 2
#define SNELL_SPEC_HAS_REFLECTION 3
#define SNELL_SPEC_HAS_LIGHTS 4
#define SNELL_SPEC_COUNT_RAYS 5
#define SNELL_SPEC_MAX_MEDIA 6
#define SNELL_SPEC_RAY_STACK 7
#define SNELL_SPEC_AMPLIFYING 8
#define SNELL_SPEC_LOOP_BUDGET 9
#define SNELL_SPEC_SHADOWS 10
#define SNELL_SPEC_COUNT 11

// Sphere::ellipsoid when the sphere is a true sphere (centre + radius).
#define SNELL_NOT_ELLIPSOID 0xffffffffu
// Slots of the counters buffer: rays by kind, then per-dispatch bookkeeping.
#define SNELL_COUNTER_PRIMARY 0
#define SNELL_COUNTER_SHADOW 1
#define SNELL_COUNTER_REFLECTED 2
#define SNELL_COUNTER_REFRACTED 3
#define SNELL_RAY_COUNTER_COUNT 4
#define SNELL_COUNTER_UNFINISHED 4  // pixels still tracing after this dispatch
#define SNELL_COUNTER_LOOP_LIMIT 5  // subgroups that may have hit the driver's loop limit
#define SNELL_COUNTER_COUNT 6

// Mesa's llvmpipe (lavapipe) ends every loop of a shader once one SIMD row has
// run 65535 loop iterations in total in a dispatch. On such a driver a pixel
// suspends its ray tree (state below) when its subgroup has spent
// SNELL_LOOP_BUDGET iterations, and the next dispatch resumes it.
#define SNELL_DRIVER_LOOP_LIMIT 65535u
#define SNELL_LOOP_BUDGET_LLVMPIPE 32768u

// Hard upper bound of the shader's per-ray medium stack.
#define SNELL_MAX_MEDIA_LIMIT 16

// One primitive. Coordinates are relative to the render's origin (a point
// just in front of the nearest geometry along the view, prepared in double on
// the host: host/gpu/GpuScene.h). A true sphere is stored by its anchor: the
// surface point P0 nearest the origin, the outward normal n0 there and the
// radius, so |f|² − r² = |o − P0|² + 2r n0·(o − P0) has no cancellation near
// the surface even for a floor of radius 10⁶. For an ellipsoid, anchorRadius
// is its centre and a bounding radius and `ellipsoid` indexes Ellipsoid.
struct Sphere {
    vec4 anchorRadius;  // xyz: P0, w: radius
    vec4 normal;        // xyz: n0 (unit), w unused
    uint material;
    uint ellipsoid;
    uint pad0;
    uint pad1;
};

// A sphere whose transform is not a similarity: the unit sphere seen through
// objectFromWorld (camera-relative world -> object). Its normal matrix is the
// transpose of objectFromWorld's linear part (SPEC §4.2: M^-T).
struct Ellipsoid {
    mat4 objectFromWorld;
};

// SPEC §2/§4 material: kd.w is the Phong exponent, kt.w the index of refraction.
struct Material {
    vec4 kd;
    vec4 ks;
    vec4 kt;
};

struct Light {
    vec4 position;  // camera-relative, w unused
    vec4 colour;    // rgb, w unused
};

// BVH node, stored in depth-first order so the shader walks it without a
// stack: an inner node's first child is the next node; `skip` is the node
// after this one's subtree (where to go on a miss, or after a leaf). A leaf
// (count > 0) holds spheres [first, first + count).
struct BvhNode {
    vec4 lower;
    vec4 upper;
    uint first;
    uint count;
    uint skip;
    uint pad0;
};

// A pixel's progress between dispatches (one per pixel of the tile).
struct PixelState {
    vec4 sum;       // rgb: sum of the finished samples and of the current one so far
    uint started;   // samples started
    uint pending;   // rays waiting on this pixel's stack
    uint done;
    uint pad0;
};

// A ray waiting to be traced (SPEC §4 ray tree, depth first). Its medium stack
// is kept beside it in the media buffer.
struct PendingRay {
    vec4 origin;     // xyz
    vec4 direction;  // xyz, unit
    vec4 weight;     // rgb: product of the ks/kt factors along its path
    uint depth;
    uint fromSphere; // the sphere whose surface it starts on
    uint inward;     // 1 if it heads into that sphere
    uint mediaCount;
};

// Per-render parameters (uniform buffer). The primary ray through the image
// point with pixel coordinates (x, y) has direction
//   normalize(cornerDir + x * pixelRight + y * pixelDown)       (SPEC §3)
// from the eye; it starts at distance primaryStart.w along that direction,
// before any geometry, where coordinates are small.
struct FrameParams {
    vec4 primaryStart;  // xyz: eye minus origin; w: distance D along each primary ray where it starts
    vec4 cornerDir;     // xyz: image-plane corner (pixel coords 0,0) minus eye
    vec4 pixelRight;    // xyz: one pixel step along a row
    vec4 pixelDown;     // xyz: one pixel step down a column
    vec4 background;    // rgb background, w = eta of air
    vec4 ambient;       // rgb ambient, w = minimum ray weight
    uint imageWidth;
    uint imageHeight;
    uint supersample;
    uint maxDepth;
    uint sphereCount;
    uint lightCount;
    uint bvhNodeCount;
    uint firstSample;   // trace sub-pixel samples firstSample .. firstSample + sampleCount − 1
    uint sampleCount;   // of the supersample² grid (row-major), and output their mean
    uint pad0;
    uint pad1;
    uint pad2;
};

// Push constants: the tile of the image this dispatch covers.
struct TileParams {
    uint originX;
    uint originY;
    uint width;
    uint height;
};

#ifdef __cplusplus
}  // namespace snell::gpu
#endif
#undef SNELL_CONST
#endif
