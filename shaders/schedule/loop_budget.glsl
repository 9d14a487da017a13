// The loop budget: old llvmpipe (Mesa 22.3's lavapipe) ends any loop after
// 65 535 iterations of a SIMD row without a word, so on such a driver a
// subgroup counts its loop passes and its invocations suspend (their state
// saved, trace.comp) before the limit; the next dispatch resumes them. A
// driver without the limit gets LOOP_BUDGET 0 and all of this compiles out.
// Every loop of the kernel is used the same way: tick() once a pass, and the
// loops that may stop there (the pixel loop, the light loop) ask
// loopBudgetSpent() first, with every lane of the subgroup in the loop.

// Loop iterations a subgroup may spend in one dispatch before its invocations
// suspend; 0: no limit (drivers without llvmpipe's old loop limiter).
layout(constant_id = SNELL_SPEC_LOOP_BUDGET) const uint LOOP_BUDGET = 0u;

// Loop iterations this subgroup has run in this dispatch, as llvmpipe's loop
// limiter counts them (at least): it counts every pass of a loop with some lane
// active, and one more, masked, that ends it; and a loop that no lane enters
// still runs that one pass, loops nested in it included, as old llvmpipe
// executes both sides of every branch. One lane of the active ones counts
// each pass, so the subgroup's sum is the count. The masked passes no lane
// can count: code that every lane runs counts them ahead, for each loop (and
// those nested in it) that the code after it may reach. The shader's loops
// are the passes over rays, over lights, of the BVH walk or the sphere loop,
// and of takePixel's search for a share with pixels left; the rest are
// unrolled. Counting too few lets the driver end a loop early (a walk cut
// short: a sphere missed); too many only suspends sooner.
uint loopTicks = 0u;
void tick(uint passes) {
    if (LOOP_BUDGET != 0u && subgroupElect()) loopTicks += passes;
}

// Whether the subgroup has spent its budget (all its lanes must take part).
bool loopBudgetSpent() { return LOOP_BUDGET != 0u && subgroupAdd(loopTicks) >= LOOP_BUDGET; }

// At the end of a dispatch: past the driver's limit some loop may have been
// cut short, and the image would be wrong; the host says so.
void reportLoopLimit() {
    if (LOOP_BUDGET == 0u) return;
    uint spent = subgroupAdd(loopTicks);  // all lanes take part
    if (subgroupElect() && spent >= SNELL_DRIVER_LOOP_LIMIT) atomicAdd(counters[SNELL_COUNTER_LOOP_LIMIT], 1u);
}
