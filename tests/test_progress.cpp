// The progress bar's time left (cli/Progress): which expectation it trusts,
// and what it does when a region outlasts its expectation. Times are given,
// not measured, so these tests are exact.
#include <cmath>

#include <gtest/gtest.h>

#include "cli/Progress.h"

using snell::cli::Progress;

namespace {

// Four regions, each a quarter of the bar; region i is done at fraction (i + 1) / 4.
constexpr double kQuarter = 0.25;
// Where a test is not about rays: no rays reported (the region's pixels are its progress).
constexpr double kNoRays = 0.0;

TEST(ProgressTimeLeft, WithoutAnExpectationFollowsThePixelsPace) {
    Progress progress(false);
    EXPECT_DOUBLE_EQ(progress.secondsLeft(10.0, 0.25, kNoRays), 30.0);
}

TEST(ProgressTimeLeft, TrustsTheRaysWhereTheyPredictedTheFinishedRegions) {
    Progress progress(false);
    // The probe's time says the regions cost the same; its rays say the last two cost 4x.
    progress.expectCost({10, 10, 10, 10}, {1e6, 1e6, 4e6, 4e6});
    progress.secondsLeft(1.0, 1 * kQuarter, kNoRays);
    progress.secondsLeft(2.0, 2 * kQuarter, kNoRays);
    // The third region took 4 s, as its rays foretold: the last one takes 4 s too.
    const double left = progress.secondsLeft(6.0, 3 * kQuarter, kNoRays);
    EXPECT_NEAR(left, 4.0, 0.2);
}

TEST(ProgressTimeLeft, TrustsTheProbesTimeWhereItPredictedTheFinishedRegions) {
    Progress progress(false);
    // The rays say the regions cost the same; the probe's time says the last two cost 3x.
    progress.expectCost({1, 1, 3, 3}, {1e6, 1e6, 1e6, 1e6});
    progress.secondsLeft(2.0, 1 * kQuarter, kNoRays);
    progress.secondsLeft(4.0, 2 * kQuarter, kNoRays);
    const double left = progress.secondsLeft(10.0, 3 * kQuarter, kNoRays);
    EXPECT_NEAR(left, 6.0, 0.3);
}

TEST(ProgressTimeLeft, ARegionPastItsExpectationSlowsThePaceOfTheRest) {
    Progress progress(false);
    progress.expectCost({1, 1, 1, 1}, {1e6, 1e6, 1e6, 1e6});
    progress.secondsLeft(1.0, 1 * kQuarter, kNoRays);
    // Region 1 was expected to take 1 s and has had 5 for half its pixels:
    // it has about 5 s left, and the two after it are taken at a pace slower
    // than the first region's (1 s each), and no slower than its own (5 s each).
    const double left = progress.secondsLeft(6.0, 1.5 * kQuarter, kNoRays);
    EXPECT_GT(left, 5.0 + 2 * 1.0);
    EXPECT_LE(left, 5.0 + 2 * 5.0);
}

TEST(ProgressTimeLeft, RegionsTheProbeTimedAtNothingGiveAFiniteTimeLeft) {
    Progress progress(false);
    // A tiny first region can take no measurable time.
    progress.expectCost({0, 1, 1, 1}, {1e3, 1e6, 1e6, 1e6});
    const double left = progress.secondsLeft(0.5, 0.1, kNoRays);
    EXPECT_TRUE(std::isfinite(left));
    EXPECT_GE(left, 0.0);
}

TEST(ProgressTimeLeft, ARegionAloneLearnsItsPaceFromItsOwnProgress) {
    Progress progress(false);
    // The probe says 100 s and 1e8 rays; after 10 s half the pixels are
    // finished and their 4e7 rays with them: 4e7 of 4e7 + 0.5 * 1e8 is 4/9
    // of the region, so 12.5 s are left, whatever the probe's time said.
    progress.expectCost({100}, {1e8});
    EXPECT_NEAR(progress.secondsLeft(10.0, 0.5, 4e7), 12.5, 1e-9);
}

TEST(ProgressTimeLeft, ARegionsOwnPaceCountsForMoreAsItGoesOn) {
    Progress progress(false);
    progress.expectCost({10, 10}, {1e6, 1e6});
    progress.secondsLeft(10.0, 0.5, 1e6);  // region 0 took its 10 s
    // Region 1 runs three times as fast as expected: the estimate lies
    // between the expectation's remainder and the region's own, nearer the
    // latter the further the region is.
    const double early = progress.secondsLeft(11.0, 0.5 + 0.5 * 0.3, 1e6 + 0.3e6);  // own: 2.33 s; expected: 9 s
    const double late = progress.secondsLeft(13.0, 0.5 + 0.5 * 0.9, 1e6 + 0.9e6);   // own: 0.33 s; expected: 7 s
    EXPECT_LT(early, 9.0);
    EXPECT_GT(early, 2.33);
    EXPECT_LT(late, 1.5);
    EXPECT_LT(late, early);
    EXPECT_GT(late, 0.33);
}

TEST(ProgressTimeLeft, ARegionPastItsExpectationWithNoProgressIsNotDone) {
    Progress progress(false);
    progress.expectCost({1, 1}, {1e6, 1e6});
    progress.secondsLeft(1.0, 0.5, 1e6);
    // The last region was expected to take 1 s, has had 3 and finished nothing yet.
    EXPECT_GT(progress.secondsLeft(4.0, 0.5, 1e6), 0.0);
}

TEST(ProgressTimeLeft, NothingLeftWhenEveryRegionIsDone) {
    Progress progress(false);
    progress.expectCost({1, 2}, {1e6, 2e6});
    EXPECT_DOUBLE_EQ(progress.secondsLeft(3.0, 1.0, kNoRays), 0.0);
}

TEST(ProgressTimeLeft, AShareOfTimeIsTheRenderersForecastOfItsRegion) {
    Progress progress(false);
    // The renderer reports its region by the share of its time done
    // (RenderRequest::expectedCost): half of the last region in 2 s leaves 2 s,
    // whatever the probe expected of it.
    progress.expectCost({1, 10}, {1e6, 1e6}, true);
    progress.secondsLeft(1.0, 0.5, kNoRays);
    EXPECT_DOUBLE_EQ(progress.secondsLeft(3.0, 0.75, kNoRays), 2.0);
}

TEST(ProgressTimeLeft, AShareOfPixelsIsWeighedAgainstTheExpectation) {
    Progress progress(false);
    // The same as a share of pixels: the probe's 10 s for the region still counts.
    progress.expectCost({1, 10}, {1e6, 1e6});
    progress.secondsLeft(1.0, 0.5, kNoRays);
    EXPECT_GT(progress.secondsLeft(3.0, 0.75, kNoRays), 2.0);
}

}  // namespace

namespace {

TEST(ProgressTimeLeft, AlikeRegionsTakeWhatTheFinishedOnesTook) {
    Progress progress(false);
    // Interleaved tiles: the probe expects 1 s each, the first took 10 s. The
    // second, 5 s in, says it is nine tenths done (its forecast errs in its
    // last pixels): it is taken to need 5 s more, and the other two 10 s each.
    progress.expectCost({1, 1, 1, 1}, {1e6, 1e6, 1e6, 1e6}, true, true);
    progress.secondsLeft(10.0, 1 * kQuarter, kNoRays);
    EXPECT_NEAR(progress.secondsLeft(15.0, 1.9 * kQuarter, kNoRays), 25.0, 1e-9);
    // Past what the first took, its own pace says: 12 s in at nine tenths.
    EXPECT_NEAR(progress.secondsLeft(22.0, 1.9 * kQuarter, kNoRays), 12.0 / 0.9 * 0.1 + 2 * 22.0 / 2.0, 1e-9);
}

}  // namespace
