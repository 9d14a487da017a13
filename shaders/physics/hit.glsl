// SPEC §4.1 and §4.3: the closest surface a ray meets (findHit, closestHit)
// and whether any surface blocks a segment (occluded), by brute force over
// the spheres, snell's BVH walk (bvh_walk.glsl) or the device's ray queries.
// The intersection maths is intersect.glsl's (explained in
// host/reference/Intersect.h); here a sphere is fetched and the ray's
// relation to it decided. Pure but for one hook: each pass of a search loop
// is reported to the scheduler, which counts it towards lavapipe's loop limit
// and, when measuring, its lanes (schedule/counters.glsl).
#ifndef SNELL_PHYSICS_HIT_GLSL
#define SNELL_PHYSICS_HIT_GLSL

void sphereLoopPass();  // a pass over the spheres
void walkLoopPass();    // a pass of a BVH walk or of a ray query

real intersectSphere(uint index, rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start) {
    uint mode = index == fromSphere ? start : ELSEWHERE;
    rvec4 anchor = SPHERE_COUNT > 0u ? preloadedAnchor[index] : sphereAnchor(index);
    rvec4 normal = SPHERE_COUNT > 0u ? preloadedNormal[index] : sphereNormal(index);
    bool ellipsoid = SPHERE_COUNT > 0u ? ((ELLIPSOID_MASK >> index) & 1u) != 0u : anchor.w < 0.0;
    if (HAS_ELLIPSOIDS && ellipsoid) {
        rmat4 objectFromWorld = SPHERE_COUNT > 0u ? preloadedEllipsoid[index] : ellipsoidMatrix(uint(-anchor.w) - 1u);
        return intersectEllipsoid(objectFromWorld, normal.w, origin, originLength, dir, mode);
    }
    return intersectTrueSphere(anchor, normal, origin, originLength, dir, mode);
}

// The rivalry of a search (margins.glsl): the nearest crossing's margin and
// whether it may be a miss, and the nearest any other sphere may be met by
// the exact ray. The closest hit is undecided when that rival may come first.
real bestMargin;
bool bestGrazing;
real rivalFrom;
// Its reach (margins.glsl): offAt where the ray passes closest to a true
// sphere's centre, scaled by the sphere's anchor, is at most offAt with
// FrameParams.sphereExtent for both (no true sphere's point lies farther from
// the origin), the rounding of `along` added.
void beginSearch(rvec2 off, rvec3 origin, real originLength, rvec3 dir) {
    searchOff = off;
    bestMargin = 0.0;
    bestGrazing = false;
    rivalFrom = NO_HIT;
    if (DECISIONS) {
        real extent = real(frame.sphereExtent);
        real along = max(extent - dot(origin, dir), 0.0) + 4.0 * UNIT_ROUNDOFF * (extent + originLength);
        searchReach = offAt(off, along, originLength + extent);
    }
}
// The crossing t of sphere i (just computed): nearer than tHit, it is the hit.
void offer(real t, uint i, inout real tHit, inout uint hit) {
    if (t < tHit) {
        if (DECISIONS) {
            rivalFrom = min(rivalFrom, tHit - bestMargin);
            bestMargin = crossingMargin;
            bestGrazing = crossingGrazing;
        }
        tHit = t;
        hit = i;
    } else if (DECISIONS) {
        rivalFrom = min(rivalFrom, crossingRival);
    }
}
// How far beyond the hit a box may hold a rival: twice the hit's margin
// stands for the rival's own (CpuSearch.cpp, Rivalry::cull).
real cullSlack() { return DECISIONS ? 2.0 * bestMargin : 0.0; }
bool closestUndecided(real tHit) { return bestGrazing || (rivalFrom < NO_HIT && rivalFrom <= tHit + bestMargin); }
// A visibility search that found `hit` (or none) before `distance`: a blocker
// within its margin of either end or that may be a miss, or a near miss before
// the light where none was found. (The search ends at the first blocker: one
// unsure while a sure one lies further counts as undecided too.)
bool blockUndecided(uint hit, real tHit, real distance) {
    return hit != NONE ? bestGrazing || tHit + bestMargin >= distance : rivalFrom < distance;
}

// Word i of the BVH's nodes, through whichever the driver reads faster: the
// texel view or the buffer's device address (shared_layout.h).
uvec4 bvhWord(int i) {
    if (BVH_WORDS) return fromHalves(BvhWords(uvec2(frame.bvhAddressLow, frame.bvhAddressHigh)).words[i]);
    return texelFetch(bvhTexels, i);
}

#include "bvh_walk.glsl"

uint traverseBvh(rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start, bool anyHit,
                 inout real tHit) {
    rvec3 inverseDir = safeInverse(dir);
    uint hit = NONE;
    uint entry = 0u;
    uint depth = 0u;
    bool walking = true;
    while (walking) {
        walkLoopPass();
        walkPass(entry, depth, walking, tHit, hit, origin, originLength, dir, inverseDir, fromSphere, start, anyHit);
    }
    return hit;
}

#ifdef SNELL_RAY_QUERY
// The same search through the driver's traversal (VK_KHR_ray_query; on a GPU
// with ray-tracing hardware, that hardware): it reports each sphere whose box
// (rounded outwards, so it holds the sphere) the ray enters within tHit, and
// the exact test of intersect.glsl, with its no-epsilon rules, decides as in
// the walk above. A hit nearer than tHit is handed back to the query, which
// then culls the boxes beyond it.
uint queryBoxes(rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start, bool anyHit,
                inout real tHit) {
    rayQueryEXT query;
    rayQueryInitializeEXT(query, sphereBoxes, gl_RayFlagsNoneEXT, 0xffu, origin, 0.0, dir, tHit);
    uint hit = NONE;
    while (rayQueryProceedEXT(query)) {
        walkLoopPass();
        uint i = uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, false));
        real t = intersectSphere(i, origin, originLength, dir, fromSphere, start);
        bool nearer = t < tHit;
        offer(t, i, tHit, hit);
        if (nearer) {
            rayQueryGenerateIntersectionEXT(query, t);
            if (anyHit) rayQueryTerminateEXT(query);
        }
    }
    return hit;
}
#endif

// The BVH search of this build: the driver's traversal, else snell's walk.
uint searchBvh(rvec3 origin, real originLength, rvec3 dir, uint fromSphere, uint start, bool anyHit,
               inout real tHit) {
#ifdef SNELL_RAY_QUERY
    return queryBoxes(origin, originLength, dir, fromSphere, start, anyHit, tHit);
#else
    return traverseBvh(origin, originLength, dir, fromSphere, start, anyHit, tHit);
#endif
}

// SPEC §4.1: the closest hit with t > 0; returns the sphere index or NONE.
// (Its margins, for a ray off by `off`: beginSearch, offer.)
uint closestHit(rvec3 origin, rvec3 dir, uint fromSphere, uint start, rvec2 off, out real tHit) {
    tHit = NO_HIT;
    real originLength = length(origin);
    beginSearch(off, origin, originLength, dir);
    if (USE_BVH) return searchBvh(origin, originLength, dir, fromSphere, start, false, tHit);
    uint hit = NONE;
    if (SPHERE_COUNT > 0u) {
        [[unroll]] for (uint i = 0u; i < SPHERE_COUNT; ++i)
            offer(intersectSphere(i, origin, originLength, dir, fromSphere, start), i, tHit, hit);
        return hit;
    }
    for (uint i = 0u; i < frame.sphereCount; ++i) {
        sphereLoopPass();
        offer(intersectSphere(i, origin, originLength, dir, fromSphere, start), i, tHit, hit);
    }
    return hit;
}

// SPEC §4.3 visibility: does any surface cross the open segment (0, distance)?
// Stops at the first occluder.
// A ray that starts on a sphere headed into it (shading a hit from inside)
// crosses that sphere at its chord unless the light is nearer: that one test
// first spares the search its answer. (Not where the spheres are unrolled: a
// dynamic index into them costs more than it spares.)
bool crossesOwnSphere(rvec3 origin, real originLength, rvec3 dir, real distance, uint fromSphere, uint start) {
    if (!((USE_BVH || SPHERE_COUNT == 0u) && start == ENTERING)) return false;
    real t = intersectSphere(fromSphere, origin, originLength, dir, fromSphere, start);
    // Only a sure crossing spares the search (margins.glsl).
    return t < distance && (!DECISIONS || (!crossingGrazing && t + crossingMargin < distance));
}

// off: how far the ray may be from the exact one; undecided: the exact ray's
// answer may differ (blockUndecided).
bool occluded(rvec3 origin, rvec3 dir, real distance, uint fromSphere, uint start, rvec2 off, out bool undecided) {
    real originLength = length(origin);
    undecided = false;
    beginSearch(off, origin, originLength, dir);
    if (crossesOwnSphere(origin, originLength, dir, distance, fromSphere, start)) return true;
    real tHit = distance;
    uint hit = NONE;
    if (USE_BVH) {
        hit = searchBvh(origin, originLength, dir, fromSphere, start, true, tHit);
    } else if (SPHERE_COUNT > 0u) {
        [[unroll]] for (uint i = 0u; i < SPHERE_COUNT; ++i) {
            if (hit == NONE) offer(intersectSphere(i, origin, originLength, dir, fromSphere, start), i, tHit, hit);
        }
    } else {
        for (uint i = 0u; i < frame.sphereCount && hit == NONE; ++i) {
            sphereLoopPass();
            offer(intersectSphere(i, origin, originLength, dir, fromSphere, start), i, tHit, hit);
        }
    }
    if (DECISIONS) undecided = blockUndecided(hit, tHit, distance);
    return hit != NONE;
}

// 1–2. The closest hit of ray r (SPEC §4.1), and what shading needs there:
// the material, the point, and the shading normal N. False on a miss. A ray
// that resumes shading (resumeShading > 0) finds the same hit again.
bool findHit(Ray r, out Hit h) {
    real t;
    // A covered ray's light is already its ancestor's widening (ray.glsl):
    // its decisions count for nothing, so it keeps no offset.
    rvec2 off = r.covered ? rvec2(0.0) : r.off;
    h.sphere = closestHit(r.origin, r.dir, r.fromSphere, r.inward ? ENTERING : LEAVING, off, t);
    h.undecided = DECISIONS && closestUndecided(t);
    if (h.sphere == NONE) return false;
    uint material = sphereMaterial(h.sphere);
    h.kd = materialKd(material);
    h.ks = materialKs(material);
    h.kt = HAS_REFRACTION ? materialKt(material) : vec4(0.0);
    // The hit point o + t d, not re-projected onto the surface: re-projecting
    // (centre + r n̂, or normalising the object-space point) rounds at the
    // scale of the centre or of the largest semi-axis, which for a big floor
    // sphere near the camera is 100× the error of o + t d. Self-intersection
    // needs no point exactly on the surface (see intersectSphere).
    rvec3 o = r.origin;
    rvec3 d = r.dir;
    h.point = o + t * d;
    rvec4 anchor = sphereAnchor(h.sphere);
    rvec3 outward;
    // How fast the normal turns as the point moves (CpuRenderer::outwardNormal).
    if (HAS_ELLIPSOIDS && anchor.w < 0.0) {
        rmat4 objectFromWorld = ellipsoidMatrix(uint(-anchor.w) - 1u);
        rvec3 p = (objectFromWorld * rvec4(o, 1.0)).xyz + t * (rmat3(objectFromWorld) * d);
        rmat3 m = rmat3(objectFromWorld);
        rvec3 n = transpose(m) * p;
        if (DECISIONS) h.turning = turningOf(transpose(m) * m, n);
        outward = normalize(n);
    } else {
        h.turning = 1.0 / anchor.w;
        outward = normalize(o - anchor.xyz + t * d + anchor.w * sphereNormal(h.sphere).xyz);
    }
    real facing = dot(d, outward);
    h.fromOutside = facing < 0.0;
    h.normal = h.fromOutside ? outward : -outward;
    // How sure: the point, its normal, and which side the ray came from.
    h.distance = t;
    h.rounding = CHAIN * UNIT_ROUNDOFF * (length(o) + t);
    h.pointOff = bestMargin + h.rounding;
    h.normalOff = normalOffset(h.pointOff, h.turning);
    h.viewTilt = off.y;
    if (DECISIONS && abs(facing) <= facingMargin(off.y, h.normalOff)) h.undecided = true;
    return true;
}

#endif
