// Which pixel an invocation takes next: shares, helpers and their bitmaps.
#ifndef SNELL_SCHEDULE_PIXELS_GLSL
#define SNELL_SCHEDULE_PIXELS_GLSL

// The invocation's next pixel of the tile. The tile is dealt in W shares of
// runs of a workgroup's size (run r to share r mod W), one share a
// workgroup, each with its counter of pixels taken, on a cache line of its
// own (one counter for the whole tile moved between the cores at every
// pixel, which cost more than it won on cheap scenes). An invocation takes
// the next pixel of its workgroup's share not yet taken, so while the share
// has pixels left no lane idles beside a lane whose pixel is expensive (a
// fixed share each left most lanes of a subgroup waiting on the one with the
// deep glass tree or the long BVH walks). Where trees diverge (refraction, a
// BVH) an invocation whose share is taken helps with the other workgroups'
// in turn, so no lane and no core idles while any share has pixels left:
// the end of each share no longer leaves its lanes idle, nor the end of the
// tile a core. (lavapipe runs a workgroup to its end on one thread: a
// workgroup goes on through the shares of those queued behind it, which
// then find them taken.) Elsewhere it stops: on gonzalez-originalTest,
// cheap and even, helping cost 15–21 % (docs/log/lane-occupancy.md, "Help with the other shares"). The host
// decides (ComputeRenderer::specialise) and reads the tile's progress by it.
layout(constant_id = SNELL_SPEC_HELPS) const bool HELPS = false;
uint takeFromHelpedShare() {
    const uint size = uint(SNELL_WORKGROUP_SIZE);
    uint taken = atomicAdd(counters[SNELL_COUNTER_COUNT + helpedShare * SNELL_COUNTER_STRIDE], 1u);
    return taken / size * invocations + helpedShare * size + taken % size;
}
// Which shares may have pixels left, as bits (shared_layout.h): a bit a
// share, and above them a bit a word of those, set while the word is not 0.
// They spare a helper an atomic on every share taken: on a GPU, thousands of
// workgroups each walking thousands of shares cost more than the tile.
uint shareWords() { return SNELL_SHARE_WORDS(gl_NumWorkGroups.x); }
// The counter holding share s's bit, and that holding share word w's bit.
uint shareBitsAt(uint s) { return SNELL_SHARE_BITS_AT(gl_NumWorkGroups.x) + s / 32u; }
uint wordBitsAt(uint w) { return SNELL_WORD_BITS_AT(gl_NumWorkGroups.x) + w / 32u; }
// Share s has no pixel left: its bit cleared, and its word's once that is 0
// (the clear that empties a word is the one that sees it go).
void shareTaken(uint s) {
    uint old = atomicAnd(counters[shareBitsAt(s)], ~(1u << (s % 32u)));
    if (old == 1u << (s % 32u)) atomicAnd(counters[wordBitsAt(s / 32u)], ~(1u << (s / 32u % 32u)));
}
// The first share word at or after word w, in turn, whose bit is set; NONE where none is.
uint nextWordLeft(uint w) {
    const uint count = (shareWords() + 31u) / 32u;
    uint k = w / 32u;
    uint bits = counters[wordBitsAt(w)] & ~((1u << (w % 32u)) - 1u);
    tick(1u);  // the pass that ends the loop (loop_budget.glsl)
    for (uint n = 0u; n <= count; ++n) {
        tick(1u);
        if (bits != 0u) return k * 32u + uint(findLSB(bits));
        k = k + 1u == count ? 0u : k + 1u;
        bits = counters[wordBitsAt(k * 32u)];
    }
    return NONE;
}
// The next share after s, in turn, that may have pixels left; NONE where none has.
uint nextShareLeft(uint s) {
    uint rest = counters[shareBitsAt(s)] & ~((2u << (s % 32u)) - 1u);
    if (rest != 0u) return s / 32u * 32u + uint(findLSB(rest));
    const uint words = shareWords();
    uint w = s / 32u;
    tick(2u);  // the pass that ends the loop, and nextWordLeft's in it
    for (uint n = 0u; n <= words; ++n) {
        tick(1u);
        w = nextWordLeft(w + 1u == words ? 0u : w + 1u);
        if (w == NONE) return NONE;
        uint bits = counters[shareBitsAt(w * 32u)];
        if (bits != 0u) return w * 32u + uint(findLSB(bits));
        // Emptied since its word's bit was read: on past it.
    }
    return NONE;
}
uint takePixel() {
    uint pixel = takeFromHelpedShare();
    if (!HELPS) return min(pixel, tilePixels);
    // Each failed take clears its share's bit, and bits are only cleared, so
    // this ends. These loops count towards the loop budget like the others.
    tick(3u);  // the pass that ends the loop, and those of the two loops in it
    while (pixel >= tilePixels) {
        tick(1u);
        shareTaken(helpedShare);
        uint next = nextShareLeft(helpedShare);
        if (next == NONE) return tilePixels;
        helpedShare = next;
        pixel = takeFromHelpedShare();
    }
    return pixel;
}

// The image's pixel of the tile's pixel p (TileParams).
uvec2 imagePixel(uvec2 p) {
    const uvec2 run = uvec2(SNELL_TILE_COLUMN_RUN, SNELL_TILE_ROW_RUN);
    uvec2 inRun = p % run;
    return uvec2(tile.originX, tile.originY) + (p - inRun) * uvec2(tile.strideX, tile.strideY) + inRun;
}

#endif
