// The one declaration of everything the host and the compute shader share:
// binding numbers, workgroup size, specialization-constant ids and the structs
// of the scene's buffers. Included by C++ (host/gpu/GpuScene.h) and by GLSL
// (shaders/trace.comp). Members are vec4, mat4, uint or float only, the
// 4-byte scalars after the vectors (never vec3), so std140, std430 and C++
// agree without padding rules; host/gpu/GpuScene.h static_asserts sizes.
//
// The scene is read-only and reaches the shader as uniform texel buffers, each
// struct below a run of RGBA32 texels (its vec4 members in order): texel
// fetches gather a SIMD row's values in one vectorised step on lavapipe, about
// 3x cheaper than the bounds-checked per-lane loads of a storage buffer
// (docs/log/drivers-and-kernel.md, "What lavapipe charges for"), and they count elements (2^27 texels on lavapipe), so
// the documented limit of 4 000 000 spheres fits where 128 MiB of storage
// buffer does not. Every view is RGBA32UI: integers are read as they are,
// floats by their bits (uintBitsToFloat), exact either way. The
// BVH can also be read through its buffer's device address
// (FrameParams.bvhAddress, GL_EXT_buffer_reference): Mesa 25's lavapipe calls
// a function for every texel fetch, which in the walk's seven fetches a node
// costs more than loads; and it loads from an address without the per-lane
// bounds checks of a storage buffer, nor its 128 MiB limit, each word as two
// 64-bit halves (wide_words.glsl; docs/log/bvh-walk.md, "The BVH as a storage
// buffer", "The walk's floor", "Words loaded as 64-bit halves").
#ifndef SNELL_SHARED_LAYOUT_H
#define SNELL_SHARED_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace snell::gpu {
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using uint = std::uint32_t;
#endif

// Workgroup: 64 invocations in a row. Invocations are persistent: each one
// renders a sequence of pixels (shaders/trace.comp), so the shape of the
// workgroup says nothing about the image.
#define SNELL_WORKGROUP_SIZE 64

// Descriptor set 0. Storage buffers: what the shader writes.
#define SNELL_BINDING_OUTPUT 0         // OutputPixel pixels[]: the tile, row-major
#define SNELL_BINDING_COUNTERS 1
#define SNELL_BINDING_SLOT_STATES 2
#define SNELL_BINDING_RAY_STACK 3
#define SNELL_BINDING_MEDIA_STACK 4
// Uniform buffer: the render's parameters.
#define SNELL_BINDING_FRAME 5
// Uniform texel buffers: the scene, every view RGBA32UI, floats by their bits
// (lavapipe compiles its texel-fetch functions for each new format a view
// has, about a millisecond each: one format for all of them saves two).
#define SNELL_BINDING_SPHERES 6           // Sphere
#define SNELL_BINDING_SPHERE_MATERIALS 7  // the material of each sphere, four a texel
#define SNELL_BINDING_ELLIPSOIDS 8        // Ellipsoid
#define SNELL_BINDING_MATERIALS 9         // Material
#define SNELL_BINDING_LIGHTS 10           // Light
#define SNELL_BINDING_BVH 11              // BvhNode
// Uniform buffer: the spheres of a scene small enough to need no BVH
// (SphereBlock; for fp64 followed by their low parts), which the shader's
// loops read at one index for the whole SIMD row (a scalar load).
#define SNELL_BINDING_SPHERE_BLOCK 12
// Uniform texel buffer: each sphere's SphereReach (where SNELL_SPEC_REACH).
#define SNELL_BINDING_REACH 13
#define SNELL_BINDING_COUNT_FP32 14
// The fp64 shader (--precision fp64) reads scene values as float pairs hi + lo
// (hi = float(v), lo = float(v - hi): 48 bits of the host's double): the hi
// parts are the buffers above, the lo parts twin buffers of the same layout.
#define SNELL_BINDING_FRAME_LOW 14
#define SNELL_BINDING_SPHERES_LOW 15
#define SNELL_BINDING_ELLIPSOIDS_LOW 16
#define SNELL_BINDING_LIGHTS_LOW 17
#define SNELL_BINDING_RAY_STACK_LOW 18
#define SNELL_BINDING_COUNT 19
// The ray-query shader (fp32 only; --traversal ray-query) reads the spheres'
// boxes as an acceleration structure (VK_KHR_acceleration_structure), the
// driver's own traversal in place of the BVH walk: one geometry of AABBs,
// primitive i the box of sphere i, in one instance.
#define SNELL_BINDING_ACCELERATION 19
#define SNELL_BINDING_LIMIT 20  // one past the largest binding

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
#define SNELL_SPEC_SPHERE_COUNT 11
#define SNELL_SPEC_BVH_DEPTH 12
#define SNELL_SPEC_ELLIPSOID_MASK 13
#define SNELL_SPEC_SPHERES_IN_BLOCK 14
#define SNELL_SPEC_FRONTIER 15
#define SNELL_SPEC_COUNT_LANES 16  // count the SIMD lanes busy in each loop pass (render --count-lanes)
#define SNELL_SPEC_TRAPS 17        // some material traps light (render/Truncation.h, growthTraps)
#define SNELL_SPEC_HELPS 18        // workgroups help with each other's shares of a tile (schedule/pixels.glsl, takePixel)
#define SNELL_SPEC_BVH_WORDS 19    // the walk reads the BVH's nodes through their address (FrameParams.bvhAddress)
#define SNELL_SPEC_STACK_IN_REGISTERS 20  // the walk's stack in registers (bvh_walk.glsl, pushEntry)
#define SNELL_SPEC_SHARE_SHADOW_RAYS 21  // a subgroup's shadow rays walked by all its lanes (schedule/lights.glsl, shadeLightsShared)
#define SNELL_SPEC_LIGHTS_IN_FRAME 22  // the lights are read from FrameParams.lights
#define SNELL_SPEC_STACKS_BY_ADDRESS 23  // the ray and media stacks through their addresses (FrameParams.rayStackAddress)
#define SNELL_SPEC_DECISIONS 24  // decisions keep their rounding margins (physics/margins.glsl)
#define SNELL_SPEC_BY_SAMPLE 25  // each sample's light kept apart, so that some may be re-traced alone (FlaggedSamples)
#define SNELL_SPEC_REACH 26      // each ray's light bounded by where it starts (SphereReach)
#define SNELL_SPEC_COUNT 27
// The deepest walk stack kept in registers (entries); a deeper one is an array
// at a per-lane index.
#define SNELL_REGISTER_STACK_LIMIT 32

// Slots of the counters buffer: rays by kind, then per-dispatch bookkeeping.
#define SNELL_COUNTER_PRIMARY 0
#define SNELL_COUNTER_SHADOW 1
#define SNELL_COUNTER_REFLECTED 2
#define SNELL_COUNTER_REFRACTED 3
#define SNELL_RAY_COUNTER_COUNT 4
#define SNELL_COUNTER_UNFINISHED 4  // invocations still tracing after this dispatch
#define SNELL_COUNTER_LOOP_LIMIT 5  // subgroups that may have hit the driver's loop limit
#define SNELL_COUNTER_DEEPEST 6     // the deepest ray traced (atomicMax)
#define SNELL_COUNTER_OVERFLOW 7    // rays dropped because an invocation's ray stack was full
#define SNELL_COUNTER_CANCEL 8      // set by the host while a dispatch runs: take no new pixel
// With COUNT_LANES: lane slots (subgroup size per pass of a subgroup) and
// lanes busy in them, of the trace loop (a lane busy: it traces a ray) and of
// the BVH walk (a lane busy: it walks).
#define SNELL_COUNTER_TRACE_SLOTS 9
#define SNELL_COUNTER_TRACE_BUSY 10
#define SNELL_COUNTER_WALK_SLOTS 11
#define SNELL_COUNTER_WALK_BUSY 12
#define SNELL_COUNTER_COUNT 13
// After them, for workgroup w at SNELL_COUNTER_COUNT + w · SNELL_COUNTER_STRIDE
// (a cache line each), the pixels of its share of the tile its invocations
// have taken after their first (schedule/pixels.glsl, takePixel); kept across the
// dispatches that resume a tile. After those, a bit a share, set while it
// may have pixels left, and then a bit a word of those, set while the word is
// not 0 (the host sets them all at the tile's first dispatch).
#define SNELL_COUNTER_STRIDE 16
// Where those bits lie, for a dispatch of `groups` workgroups (uint
// arithmetic in GLSL, std::uint64_t in C++): the first counter of the
// shares' bits, their count of words, the first counter of the words' bits
// and the whole buffer's count of counters.
#define SNELL_SHARE_BITS_AT(groups) (SNELL_COUNTER_COUNT + (groups) * SNELL_COUNTER_STRIDE)
#define SNELL_SHARE_WORDS(groups) (((groups) + 31u) / 32u)
#define SNELL_WORD_BITS_AT(groups) (SNELL_SHARE_BITS_AT(groups) + SNELL_SHARE_WORDS(groups))
#define SNELL_COUNTERS_FOR(groups) (SNELL_WORD_BITS_AT(groups) + (SNELL_SHARE_WORDS(groups) + 31u) / 32u)

// Mesa's llvmpipe before 24 (lavapipe in Debian 12's Mesa 22.3) ends every
// loop of a shader once one SIMD row has run 65535 loop iterations in total in
// a dispatch; newer llvmpipe has no such limit (the renderer probes the
// driver: host/gpu/DriverProbe.cpp). Under the limit an invocation
// suspends its work (SlotState, the ray stack) when its subgroup has spent
// SNELL_LOOP_BUDGET iterations, and the next dispatch resumes it.
#define SNELL_DRIVER_LOOP_LIMIT 65535u
#define SNELL_LOOP_BUDGET_LIMITED 32768u

// Hard upper bound of the shader's per-ray medium stack.
#define SNELL_MAX_MEDIA_LIMIT 16

// One sphere, as the intersection loop reads it. Coordinates are relative to
// the render's origin (a point just in front of the nearest geometry along the
// view, prepared in double on the host: host/gpu/GpuScene.h). A true sphere is
// stored by its anchor: the surface point P0 nearest the origin, the outward
// normal n0 there and the radius r > 0, so |f|² − r² = |o − P0|² + 2r n0·(o − P0)
// has no cancellation near the surface even for a floor of radius 10⁶; normal.w
// holds |P0|, the scale of the rounding in o − P0. An ellipsoid has
// anchorRadius = (centre, −1 − e), e its index among the ellipsoids (a float,
// exact below 2^24), and normal = (0, 0, 0, the largest absolute row sum of its
// linear part).
struct Sphere {
    vec4 anchorRadius;  // xyz: P0 (or the centre), w: r (or −1 − ellipsoid index)
    vec4 normal;        // xyz: n0 (unit), w: |P0| (or the ellipsoid's matrix norm)
};

// Scenes of at most SNELL_BLOCK_SPHERES spheres can be intersected without a
// BVH, from a uniform block (8 KiB; with its low parts 16 KiB, the least
// maxUniformBufferRange a Vulkan device has); up to SNELL_MAX_UNROLLED_SPHERES
// the loops over them are unrolled (host/gpu/GpuScene.h: kBvhThreshold).
#define SNELL_BLOCK_SPHERES 256
#define SNELL_MAX_UNROLLED_SPHERES 32
struct SphereBlock {
    Sphere spheres[SNELL_BLOCK_SPHERES];
};

// An ellipsoid is the unit sphere seen through objectFromWorld (camera-relative
// world -> object), an affine map stored as its three rows. Its normal matrix
// is the transpose of the linear part (SPEC §4.2: M^-T).
struct Ellipsoid {
    vec4 row0;
    vec4 row1;
    vec4 row2;
};

// SPEC §2/§4 material: kd.w is the Phong exponent, kt.w the index of
// refraction; ks.w is 1 where light can grow without end through it
// (render/Truncation.h, growthTraps), else 0.
struct Material {
    vec4 kd;
    vec4 ks;
    vec4 kt;
};

struct Light {
    vec4 position;  // camera-relative, w unused
    vec4 colour;    // rgb, w unused
};
#define SNELL_FRAME_LIGHTS 16

// A BVH node of up to four children (read as RGBA32UI, SNELL_BVH_NODE_TEXELS
// texels a node): their boxes axis by axis, lane k of each corner being child
// k's, so one ray tests all four with vector arithmetic; then their codes
// (uint bits). A child is a node's index, SNELL_BVH_LEAF | first · 4 +
// count − 1 for the leaf of spheres [first, first + count), count ≤
// SNELL_BVH_MAX_LEAF, or SNELL_BVH_EMPTY. Node 0 is the root; nodes are in
// depth-first order, so a node's first child tends to follow it.
struct BvhNode {
    vec4 lowerX;
    vec4 upperX;
    vec4 lowerY;
    vec4 upperY;
    vec4 lowerZ;
    vec4 upperZ;
    vec4 child;  // uint bits
};
#define SNELL_BVH_NODE_TEXELS 7
#define SNELL_BVH_WIDTH 4  // a node's children: the lanes of its vec4s
#define SNELL_BVH_MAX_LEAF 4
#define SNELL_BVH_LEAF 0x80000000u
#define SNELL_BVH_EMPTY 0xffffffffu

// An invocation's progress between dispatches (one per invocation). A pixel
// is traced in steps of falling cut-off: a step traces on from the rays the
// last one left under its cut-off (the frontier, a ring of SNELL_SPEC_FRONTIER
// entries after the invocation's ray stack), so the steps together trace the
// very tree of one pass at the last cut-off (render/RenderRequest.h).
struct SlotState {
    vec4 sum;        // rgb: the pixel's sum over its samples so far
    vec4 deferred;   // rgb: the weight of the rays waiting in the frontier
    vec4 lost;       // rgb: the most light of rays lost for good (depth limit, floor, tree budget, full stack)
    vec4 lower;      // rgb: the pixel's best lower and upper bounds over its steps so far
    vec4 upper;      //      (render/Truncation.h, PixelEstimate)
    vec4 settled;    // rgb: its colour after the last step, clamped (render/Truncation.h, ErrorEstimate)
    vec4 undecided;  // rgb: the most light of its rays whose light undecided decisions may change; a: the light of
                     // its undecided shadow rays, largest channel (physics/margins.glsl); over its samples
    uint pixel;      // the pixel of the tile in progress (row-major); ≥ tile size: done
    uint started;    // samples of it started
    uint pending;    // rays waiting on this invocation's stack
    uint finished;   // pixels finished so far in this tile (read by the host for progress)
    uint treeRays;   // rays the pixel's trees have traced
    uint overBudget; // 1: they reached the tree budget
    uint rays;       // rays traced so far in this tile (read by the host for progress)
    uint steps;      // steps of the current pixel finished
    uint frontierHead;   // the frontier's first entry
    uint frontierCount;  // its entries
    uint frontierOld;    // of those, the ones the last step left, still to trace in this one
    uint amplified;      // 1: its trees met a trap (a material that can grow light without end, ks.w) with light
    float cutOff;        // this step's cut-off
    float heaviestLeft;  // the heaviest ray this step left in the frontier
    float lastMove;      // how far the last step moved the colour (ErrorEstimate)
    float moveBefore;    // and the step before it
    float settledWeight; // the weight the pixel had not traced after the last step, in channels under 1, per sample
    uint droppedGrowing; // 1: light that may grow was dropped for want of room (a full frontier or ray stack)
    float shading;       // the light shading's rounding may have moved, largest channel, over its samples
    float unsureLight;   // the light its sum holds that the exact tree's may not (covered rays', ray.glsl;
                         // undecided shadow rays'), largest channel, over its samples
    // Its samples, each kept apart until its first step's tree ends (SNELL_SPEC_BY_SAMPLE; steps.glsl,
    // closeSample), so that the host may re-trace only those whose light hangs on an undecided decision:
    vec4 sampleLight;    // rgb: the current sample's light so far; a: its shading's rounding
    vec4 flagged;        // rgb: the light of its flagged samples; a: the shading's rounding of the others
    uint flaggedLow;     // bit k: its sample k (frame.firstSample + k) flagged, k < 32;
    uint flaggedHigh;    // bit k − 32: 32 <= k < 64
    uint sampleFlagged;  // 1: the current sample met an undecided decision
    float undecidedLocal;  // the most light one hit of its undecided rays returns (RadianceBound::local), largest channel
    vec4 deferredLight;  // rgb: the most light the rays waiting in the frontier can bring (render/Reach.h)
};

// Where a pixel traced one step with SNELL_SPEC_BY_SAMPLE on, its flagged
// samples (SlotState::flagged), written beside its OutputPixel through
// FrameParams.flaggedAddress: the host re-traces only those, where they hold
// all its undecided light (host/gpu/TileReadback.cpp, samplesToRetrace).
struct FlaggedSamples {
    vec4 light;  // rgb: their light, summed; a: the others' shading's rounding, summed
    uint low;    // SlotState::flaggedLow, flaggedHigh; both 0 where the pixel is re-traced whole, if at all
    uint high;
    uint pad0;
    uint pad1;
};

// What the shader writes for each pixel of a tile: 32 bytes, what the host
// needs and no more. Each byte is written by the kernel and read again by the
// host: at 64 bytes (the undecided weights and rounding terms as they were
// summed, the host working out the rest) the dispatch of a scene of a few
// spheres took 1.05-1.2x as long on lavapipe (docs/log/margins.md, "eighth").
struct OutputPixel {
    vec4 colour;    // rgb: the colour (unclamped); a: its truncation bound, negative where not finite
    float estimate; // the estimated error where it stopped on one (render/Truncation.h), else −1
    uint report;    // SNELL_PIXEL_* flags, and above them the rays (closest-hit queries) its trees
                    // traced, its cost (RenderRequest::rayImage)
    float excess;   // the light its colour holds that the exact one may not: covered rays', undecided
                    // shadow rays' (SlotState::unsureLight) and shading's rounding, a sample's mean
    float moved;    // what its undecided decisions and shading's rounding may have moved of its colour:
                    // their rays' weight times R (where R is not finite in a weighted channel, the
                    // most one hit returns), their shadow rays' light, SlotState::shading; a sample's mean
};
// OutputPixel::report's flags.
#define SNELL_PIXEL_OVER_BUDGET 1u          // the tree budget stopped it
#define SNELL_PIXEL_OVER_TOLERANCE 2u       // it ended over the tolerance
#define SNELL_PIXEL_DROPPED_GROWING 4u      // because light that may grow was dropped (SlotState::droppedGrowing)
#define SNELL_PIXEL_UNDECIDED 8u            // a decision of its trees was within its margin (physics/margins.glsl)
#define SNELL_PIXEL_MOVED_UNBOUNDED 16u     // and R is not finite in a channel its undecided rays weigh
#define SNELL_PIXEL_RAYS_SHIFT 5u
#define SNELL_PIXEL_RAYS_LIMIT 0x7ffffffu   // more rays than this are reported as this

// A ray waiting to be traced (SPEC §4 ray tree, depth first). Its medium stack
// is kept beside it in the media buffer.
struct PendingRay {
    vec4 origin;     // xyz; w: how far it may be from the exact ray's origin (physics/margins.glsl)
    vec4 direction;  // xyz, unit; w: how far its direction may be turned from the exact ray's
    vec4 weight;     // rgb: product of the ks/kt factors along its path
    uint depth;
    uint fromSphere; // the sphere whose surface it starts on
    uint flags;      // bit 0: it heads into that sphere; bit 31: an undecided ancestor covers its light;
                     // bits 1..30: medium-stack size
    uint resumeShading;  // 0: not shaded yet; k > 0: suspended while shading, resumes at light k − 1
};

// The most light a ray can bring per unit weight, by where it starts
// (render/Reach.h): leaving a sphere's surface outwards, or into it; one
// per sphere, in the order of the spheres (SNELL_BINDING_REACH).
struct SphereReach {
    vec4 outward;  // rgb
    vec4 inward;   // rgb
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
    vec4 background;    // rgb
    vec4 ambient;       // rgb
    vec4 radiance;      // rgb: the radiance bound R (render/Truncation.h), +inf where light need not decay
    vec4 localRadiance; // rgb: the most light one hit or miss returns, its children aside (RadianceBound::local)
    uint imageWidth;
    uint imageHeight;
    uint supersample;
    uint maxDepth;
    uint sphereCount;
    uint lightCount;
    uint bvhNodeCount;
    uint firstSample;   // trace sub-pixel samples firstSample .. firstSample + sampleCount − 1
    uint sampleCount;   // of the supersample² grid (row-major), and output their mean
    uint treeBudget;    // the most rays a pixel's trees may trace, per sample; 0: no limit
    uint estimate;      // 1: an unbounded pixel stops on its estimated error (TraceSettings::estimate)
    float minWeight;    // the weight cut-off (with a tolerance: the floor, the lowest cut-off tried)
    float tolerance;    // on each pixel's truncation bound; 0: none (a fixed tree)
    float amplifiedEstimate;  // the estimated error within which a pixel whose trees met a trap may
                              // stop (render/Truncation.h, kAmplifiedEstimate)
    float airEta;       // the index of refraction outside every sphere (SPEC §4.5)
    uint bvhAddressLow; // the device address of the BVH's nodes (with SNELL_SPEC_BVH_WORDS), low 32 bits
    uint bvhAddressHigh;
    uint rayStackAddressLow;    // the device addresses of the ray and media stacks (with
    uint rayStackAddressHigh;   // SNELL_SPEC_STACKS_BY_ADDRESS), low and high 32 bits
    uint mediaStackAddressLow;
    uint mediaStackAddressHigh;
    float sphereExtent; // no true sphere's point lies farther from the origin (rounded up; physics/hit.glsl, beginSearch)
    uint flaggedAddressLow;   // where FlaggedSamples go (SNELL_SPEC_BY_SAMPLE), low and high 32 bits
    uint flaggedAddressHigh;
    uint reachInward;   // 1: SphereReach.inward holds for this eye (render/Reach.h, inwardHolds)
    uint pad0;
    uint pad1;
    uint pad2;
    // A scene of at most SNELL_FRAME_LIGHTS lights has them here again
    // (SNELL_SPEC_LIGHTS_IN_FRAME): the lights' loop reads light j at one index
    // for the whole SIMD row, a scalar load, where a texel fetch is a call of
    // ~64 instructions on lavapipe whatever the index.
    Light lights[SNELL_FRAME_LIGHTS];
};

// Interleaved tiles (ComputeRenderer) take the image's columns in runs of a
// SIMD row's width and its rows one by one: runs that fine keep the tiles
// fair samples of a finely structured image (runs of 64 columns left the
// tiles of becker-SphereFlake2 at 1400² 16 against 29 s), and cost the
// kernel no more than coarse ones (docs/log/writing-images.md, "Interleaved tiles").
#define SNELL_TILE_COLUMN_RUN 8
#define SNELL_TILE_ROW_RUN 1

// Push constants: the tile of the image this dispatch covers, and whether it
// resumes the invocations' suspended work (SlotState) or starts afresh. A
// tile is either a block of the image (strides 1) or every strideX-th run of
// columns and strideY-th run of rows of it (ComputeRenderer: interleaved
// tiles): its pixel (x, y) is the image's (originX + (x − x mod C) · strideX
// + x mod C, originY + (y − y mod R) · strideY + y mod R), C and R the runs.
struct TileParams {
    uint originX;
    uint originY;
    uint width;
    uint height;
    uint resume;
    // Workgroup g takes share (g · workgroupStride) mod W of the tile's W
    // shares of pixels (schedule/pixels.glsl, takePixel); coprime with W.
    uint workgroupStride;
    uint strideX;
    uint strideY;
};

#ifdef __cplusplus
// Integers carried as float values in a vec4's w are exact below this.
inline constexpr uint kMaxExactIndex = 1u << 24;
}  // namespace snell::gpu
#endif
#endif
