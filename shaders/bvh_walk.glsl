// The BVH walk (SPEC §4.1's closest hit and §4.3's visibility through a BVH of
// four-wide nodes, shared_layout.h: BvhNode), shared by the renderer
// (trace.comp) and the walk's floor kernel (bvh_walk_kernel.comp). The
// includer declares before it: BVH_DEPTH and STACK_IN_REGISTERS (constants),
// NONE, uvec4 bvhWord(int) (word i of the nodes),
// real intersectSphere(index, origin, originLength, dir, fromSphere, start),
// void offer(t, index, tHit, hit) (a sphere's crossing t: the hit if nearer
// than tHit) and real cullSlack() (how far past tHit a box still counts).
#ifndef SNELL_BVH_WALK_GLSL
#define SNELL_BVH_WALK_GLSL

// Lane k of a node's vector is child k's (shared_layout.h: BvhNode).
rvec4 nodeVector(int word) { return rvec4(uintBitsToFloat(bvhWord(word))); }

rvec3 safeInverse(rvec3 d) {
    const real tiny = 1e-30;
    return 1.0 / mix(d, rvec3(tiny) * sign(d + rvec3(1e-38)), lessThan(abs(d), rvec3(tiny)));
}

// Sorts two (entry distance, child) pairs by distance.
void orderPair(inout real enterA, inout uint childA, inout real enterB, inout uint childB) {
    bool swap = enterB < enterA;
    real e = enterA;
    uint c = childA;
    enterA = swap ? enterB : enterA;
    childA = swap ? childB : childA;
    enterB = swap ? e : enterB;
    childB = swap ? c : childB;
}

// The walk's stack. Up to SNELL_REGISTER_STACK_LIMIT entries it lives in
// registers: its top is entry 0, a push moves every entry down one and a pop
// up one, each index a constant (the loops unrolled), so a push under a
// per-lane condition is a blend. At a per-lane index (the top at depth − 1,
// as in deeper trees) a store is a write to memory lane by lane, each behind
// a branch on that lane's mask, which lavapipe cannot predict where lanes
// differ. (The host sets STACK_IN_REGISTERS.)
uint bvhStack[BVH_DEPTH + 1u];  // one more: the store past the last entry
// Pushes child where the ray entered its box.
void pushEntry(uint child, bool entered, inout uint depth) {
    if (STACK_IN_REGISTERS) {
        [[unroll]] for (int i = 1; i < int(BVH_DEPTH); ++i) {
            int k = int(BVH_DEPTH) - i;
            bvhStack[k] = entered ? bvhStack[k - 1] : bvhStack[k];
        }
        bvhStack[0] = entered ? child : bvhStack[0];
    } else {
        bvhStack[depth] = child;  // stored either way: one not entered is overwritten next
    }
    depth += entered ? 1u : 0u;
}
uint popEntry(inout uint depth) {
    --depth;
    if (!STACK_IN_REGISTERS) return bvhStack[depth];
    uint top = bvhStack[0];
    [[unroll]] for (int k = 1; k < int(BVH_DEPTH); ++k) bvhStack[k - 1] = bvhStack[k];
    return top;
}

// The BVH walk shared by the closest hit and the visibility test. A node's
// four children's boxes are tested at once (a slab test a vector lane each);
// those the ray enters are taken nearest first, the others waiting on
// a short per-ray stack (at most (width − 1) · depth entries): the closest
// hit is found early and then culls the rest. A leaf is entered from the
// stack or its parent without a fetch of its own: its code says which
// spheres it holds.
// anyHit: stop at the first hit before tMax (SPEC §4.3 visibility).
//
// One pass of the walk. entry: in hand, a node's index or SNELL_BVH_LEAF | a
// leaf's code; depth: the entries on the stack; walking: false once done.
void walkPass(inout uint entry, inout uint depth, inout bool walking, inout real tHit, inout uint hit,
              rvec3 origin, real originLength, rvec3 dir, rvec3 inverseDir, uint fromSphere, uint start,
              bool anyHit) {
    // A pass takes an inner node, then the leaf in hand if there is one
    // (the node's nearest child, or the next waiting entry): one pass for
    // both, so lanes at leaves and lanes at nodes go on together.
    if ((entry & SNELL_BVH_LEAF) == 0u) {
        int base = int(entry) * SNELL_BVH_NODE_TEXELS;
        rvec4 x0 = (nodeVector(base) - origin.x) * inverseDir.x;
        rvec4 x1 = (nodeVector(base + 1) - origin.x) * inverseDir.x;
        rvec4 y0 = (nodeVector(base + 2) - origin.y) * inverseDir.y;
        rvec4 y1 = (nodeVector(base + 3) - origin.y) * inverseDir.y;
        rvec4 z0 = (nodeVector(base + 4) - origin.z) * inverseDir.z;
        rvec4 z1 = (nodeVector(base + 5) - origin.z) * inverseDir.z;
        uvec4 child = bvhWord(base + 6);
        // The slab test within [0, tHit] against boxes stored rounded outwards;
        // Ize, "Robust BVH Ray Traversal" (JCGT 2013): the exit distance is
        // widened so rounding never culls a box the ray touches.
        rvec4 enter = max(max(min(x0, x1), min(y0, y1)), max(min(z0, z1), rvec4(0.0)));
        rvec4 leave = min(min(max(x0, x1), max(y0, y1)), min(max(z0, z1), rvec4(tHit + cullSlack()))) * (1.0 + 8.0 * UNIT_ROUNDOFF);
        bvec4 enters = bvec4(uvec4(lessThanEqual(enter, leave)) & uvec4(notEqual(child, uvec4(SNELL_BVH_EMPTY))));
        // Children missed sort last, at +inf (an entered box's entry is finite).
        real never = real(uintBitsToFloat(0x7f800000u));
        rvec4 key = mix(rvec4(never), enter, enters);
        real k0 = key.x, k1 = key.y, k2 = key.z, k3 = key.w;
        uint c0 = child.x, c1 = child.y, c2 = child.z, c3 = child.w;
        // A sorting network of four.
        orderPair(k0, c0, k1, c1);
        orderPair(k2, c2, k3, c3);
        orderPair(k0, c0, k2, c2);
        orderPair(k1, c1, k3, c3);
        orderPair(k1, c1, k2, c2);
        pushEntry(c3, k3 < never, depth);
        pushEntry(c2, k2 < never, depth);
        pushEntry(c1, k1 < never, depth);
        if (k0 < never) entry = c0;
        else if (depth > 0u) entry = popEntry(depth);
        else walking = false;
    }
    if (walking && (entry & SNELL_BVH_LEAF) != 0u) {
        // A leaf: spheres first · 4 + count − 1 = code.
        uint code = entry & ~SNELL_BVH_LEAF;
        uint first = code >> 2;
        uint last = first + (code & 3u);
        [[unroll]] for (uint k = 0u; k < SNELL_BVH_MAX_LEAF; ++k) {
            uint i = first + k;
            if (i <= last) {
                offer(intersectSphere(i, origin, originLength, dir, fromSphere, start), i, tHit, hit);
            }
        }
        if ((anyHit && hit != NONE) || depth == 0u) walking = false;
        else entry = popEntry(depth);
    }
}

#endif
