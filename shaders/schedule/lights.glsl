// 3. The lights' loop of a hit, scheduled: suspended between lights where
// the loop budget is spent, or its shadow rays shared out among a subgroup's
// lanes. The physics of one light is physics/shade.glsl's shadeLight.
#ifndef SNELL_SCHEDULE_LIGHTS_GLSL
#define SNELL_SCHEDULE_LIGHTS_GLSL

layout(constant_id = SNELL_SPEC_SHARE_SHADOW_RAYS) const bool SHARE_SHADOW_RAYS = false;

// The position of the n-th (from 0) set bit of x: a binary search.
uint nthSetBit(uint x, uint n) {
    uint position = 0u;
    [[unroll]] for (uint width = 16u; width > 0u; width >>= 1u) {
        uint below = uint(bitCount(x & ((1u << width) - 1u)));
        if (n >= below) {
            n -= below;
            x >>= width;
            position += width;
        }
    }
    return position;
}

#ifndef SNELL_RAY_QUERY  // (shared shadow rays walk snell's own BVH)
// What a lane that walks another's shadow ray needs of that lane's hit:
// the point and its length, the sphere and how the ray starts on it. A slot
// for each invocation of the workgroup, by subgroup and lane.
shared rvec4 sharedHitPoint[SNELL_WORKGROUP_SIZE];
shared uint sharedHitSphere[SNELL_WORKGROUP_SIZE];
shared real sharedHitOff[SNELL_WORKGROUP_SIZE];  // its pointOff (margins.glsl)
uint sharedSlot(uint lane) { return gl_SubgroupID * gl_SubgroupSize + lane; }

// The lights' part of the local term of a hit, the subgroup's shadow rays
// shared out among its lanes. In the lights' own loop a lane walks only its own
// shadow ray, so a lane whose ray missed, whose light is behind its surface or
// whose ray leaves through its own sphere idles while the others walk (on
// SphereFlake2 1.6 lanes of 8 walked on average, 19 % of the lane slots of
// those walks busy). Here the lights go in batches of min(4, 32 / subgroup
// size): bit lane · batch + b of `casting` says that the lane casts a ray to
// the batch's light b, and the k-th of those rays is walked by the (k mod n)-th
// of the n lanes still in the pixel loop, each walking its rays one after
// another in one loop. No lane talks to another inside the walk (rays handed
// out there to whichever lanes were idle, by ballots and shuffles, cost more
// than they saved on lavapipe; docs/log/kernel-profiled.md, "Lanes refilled as their walks end"): a lane reads the hit of
// the ray's owner from workgroup memory, and after the walk one reduction tells
// each owner, by the same bits, which of its rays were blocked. It adds each
// seen light's term in light order: the same sums as shadeLight's loop. The
// host enables this on CPU devices with subgroups of up to 16 lanes only: there
// a subgroup's lanes run in lockstep, so each sees the others' hits once
// written and all meet again at the reductions after the walk (a GPU would need
// subgroup barriers), and its slots below lie within the workgroup. And without
// a loop budget only: a dispatch cannot suspend in the middle of a walk.
void shadeLightsShared(inout SlotState state, Ray r, vec3 weight, Hit h, bool shading, inout uint shadowRays) {
    rvec3 v = -r.dir;
    uint start = shadowStart(h);
    real originLength = length(h.point);
    const uint size = gl_SubgroupSize;
    const uint lane = gl_SubgroupInvocationID;
    const uint batch = min(4u, 32u / size);
    if (shading) {
        sharedHitPoint[sharedSlot(lane)] = rvec4(h.point, originLength);
        sharedHitSphere[sharedSlot(lane)] = h.sphere * 4u + start;
        if (DECISIONS) sharedHitOff[sharedSlot(lane)] = h.pointOff;
    }
    subgroupMemoryBarrierShared();
    // The walkers: every lane still in the pixel loop, in lane order.
    uint inLoop = subgroupOr(1u << lane);
    const uint walkers = uint(bitCount(inLoop)), walkerRank = uint(bitCount(inLoop & ((1u << lane) - 1u)));
    for (uint firstLight = 0u; firstLight < frame.lightCount; firstLight += batch) {
        // The rays to walk: those towards lights the surface faces, less those
        // that cross the hit sphere first.
        uint casting = 0u;
        [[unroll]] for (uint b = 0u; b < 4u; ++b) {
            bool walks = false;
            if (shading && b < batch && firstLight + b < frame.lightCount) {
                rvec3 l;
                real distance;
                if (towardsLight(firstLight + b, h, l, distance) > 0.0) {
                    if (COUNT_RAYS) countedRays[SNELL_COUNTER_SHADOW]++;
                    shadowRays++;
                    if (DECISIONS) beginSearch(shadowOff(h, distance), h.point, originLength, l);
                    walks = !crossesOwnSphere(h.point, originLength, l, distance, h.sphere, start);
                }
            }
            if (walks) casting |= 1u << b;
        }
        casting = subgroupOr(casting << (lane * batch));
        uint rays = uint(bitCount(casting));
        uint walkedBlocked = 0u, walkedUndecided = 0u;
        uint ray = walkerRank, bit = 0u, entry = 0u, depth = 0u, hit = NONE, fromSphere = 0u, fromStart = 0u;
        rvec3 origin = rvec3(0.0), l = rvec3(0.0), inverseDir = rvec3(0.0);
        real distance = 0.0, lightDistance = 0.0, rayOriginLength = 0.0;
        bool walking = ray < rays, begins = walking;
        while (walking) {
            if (begins) {
                begins = false;
                // A ray to begin: its owner's hit, and the direction to its light.
                bit = nthSetBit(casting, ray);
                rvec4 point = sharedHitPoint[sharedSlot(bit / batch)];
                uint from = sharedHitSphere[sharedSlot(bit / batch)];
                origin = point.xyz;
                rayOriginLength = point.w;
                fromSphere = from >> 2;
                fromStart = from & 3u;
                distance = lightDirection(firstLight + bit % batch, origin, l);
                lightDistance = distance;
                inverseDir = safeInverse(l);
                hit = NONE;
                if (DECISIONS) {
                    real pointOff = sharedHitOff[sharedSlot(bit / batch)];
                    beginSearch(rvec2(pointOff, pointOff / distance + CHAIN * UNIT_ROUNDOFF), origin, rayOriginLength, l);
                }
            }
            if (COUNT_LANES) countLanes(true, walkSlots, walkBusy);
            walkPass(entry, depth, walking, distance, hit, origin, rayOriginLength, l, inverseDir, fromSphere,
                     fromStart, true);
            if (!walking) {
                if (hit != NONE) walkedBlocked |= 1u << bit;
                if (DECISIONS && blockUndecided(hit, distance, lightDistance)) walkedUndecided |= 1u << bit;
                ray += walkers;
                walking = begins = ray < rays;
                entry = 0u;
                depth = 0u;
            }
        }
        uint blocked = subgroupOr(walkedBlocked);
        uint undecided = DECISIONS ? subgroupOr(walkedUndecided) : 0u;
        // Each lane's seen lights, in light order: those it cast a ray to
        // (so its surface faces them) that nothing blocked; where the answer
        // is undecided, the light's term is either answer's (shadeLight).
        [[unroll]] for (uint b = 0u; b < 4u; ++b) {
            if (b >= batch) continue;
            uint mine = 1u << (lane * batch + b);
            if ((casting & mine) == 0u || ((blocked & mine) != 0u && (undecided & mine) == 0u)) continue;
            rvec3 toLight;
            real lightDistance;
            float nl = towardsLight(firstLight + b, h, toLight, lightDistance);
            vec3 error;
            vec3 term = lightTerm(firstLight + b, h, toLight, nl, v, DECISIONS ? cosineOffset(h, lightDistance) : 0.0,
                                  error);
            if ((blocked & mine) == 0u) addLight(state, r, weighted(weight, term), (undecided & mine) != 0u);
            if (DECISIONS && (blocked & mine) == 0u && !r.covered) addShadingError(state, maxChannel(weighted(weight, error)));
            if ((undecided & mine) != 0u && !r.covered) addUndecided(state, vec4(vec3(0.0), maxChannel(weighted(weight, term))), vec3(0.0));
        }
    }
}
#endif

// 3. The lights' part of the local term of ray r at hit h, each light added
// to the pixel as it is shaded, in light order (the same sums whether or not
// shading is suspended part-way). Under a loop budget every lane runs this
// loop (shading or not), so the subgroup can check its budget between lights:
// one ray's shading may take any number of lights, over several dispatches.
// Rays that resume start where they stopped: the loop starts at the first
// light some lane still needs, so every dispatch moves on. Returns true where
// the budget suspended it (r then waits to resume at the next light).
bool shadeLights(inout SlotState state, inout Ray r, vec3 weight, Hit h, bool shading, inout uint shadowRays) {
#ifndef SNELL_RAY_QUERY
    // Every lane, shading or not, walks the subgroup's shadow rays.
    if (HAS_LIGHTS && SHARE_SHADOW_RAYS && USE_BVH && SHADOWS && LOOP_BUDGET == 0u && gl_SubgroupSize <= 16u) {
        shadeLightsShared(state, r, weight, h, shading, shadowRays);
        return false;
    }
#endif
    if (!HAS_LIGHTS || !(shading || LOOP_BUDGET != 0u)) return false;
    rvec3 v = -r.dir;
    uint firstLight = LOOP_BUDGET != 0u ? subgroupMin(shading ? max(r.resumeShading, 1u) - 1u : frame.lightCount) : 0u;
    for (uint j = firstLight; j < frame.lightCount; ++j) {
        // At least one light a dispatch, whatever the hit cost: progress.
        if (j > firstLight && loopBudgetSpent()) {
            if (shading) {
                r.resumeShading = max(r.resumeShading, j + 1u);
                r.weight = weight;
            }
            return true;
        }
        tick(2u);  // this light, and the occlusion loop should no lane enter it
        if (shading && j + 1u >= r.resumeShading) {
            bool castShadowRay;
            vec3 undecided = vec3(0.0), error = vec3(0.0);
            vec3 term = shadeLight(j, h, v, castShadowRay, undecided, error);
            if (COUNT_RAYS && castShadowRay) countedRays[SNELL_COUNTER_SHADOW]++;
            if (castShadowRay) shadowRays++;
            addLight(state, r, weighted(weight, term), maxChannel(undecided) > 0.0);
            if (DECISIONS && !r.covered) addUndecided(state, vec4(vec3(0.0), maxChannel(weighted(weight, undecided))), vec3(0.0));
            if (DECISIONS && !r.covered) addShadingError(state, maxChannel(weighted(weight, error)));
        }
    }
    return false;
}

#endif
