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

TEST(ProgressTimeLeft, WithoutAnExpectationFollowsThePixelsPace) {
    Progress progress(false);
    EXPECT_DOUBLE_EQ(progress.secondsLeft(10.0, 0.25), 30.0);
}

TEST(ProgressTimeLeft, TrustsTheRaysWhereTheyPredictedTheFinishedRegions) {
    Progress progress(false);
    // The probe's time says the regions cost the same; its rays say the last two cost 4x.
    progress.expectCost({10, 10, 10, 10}, {1e6, 1e6, 4e6, 4e6});
    progress.secondsLeft(1.0, 1 * kQuarter);
    progress.secondsLeft(2.0, 2 * kQuarter);
    // The third region took 4 s, as its rays foretold: the last one takes 4 s too.
    const double left = progress.secondsLeft(6.0, 3 * kQuarter);
    EXPECT_NEAR(left, 4.0, 0.2);
}

TEST(ProgressTimeLeft, TrustsTheProbesTimeWhereItPredictedTheFinishedRegions) {
    Progress progress(false);
    // The rays say the regions cost the same; the probe's time says the last two cost 3x.
    progress.expectCost({1, 1, 3, 3}, {1e6, 1e6, 1e6, 1e6});
    progress.secondsLeft(2.0, 1 * kQuarter);
    progress.secondsLeft(4.0, 2 * kQuarter);
    const double left = progress.secondsLeft(10.0, 3 * kQuarter);
    EXPECT_NEAR(left, 6.0, 0.3);
}

TEST(ProgressTimeLeft, ARegionPastItsExpectationSlowsThePaceOfTheRest) {
    Progress progress(false);
    progress.expectCost({1, 1, 1, 1}, {1e6, 1e6, 1e6, 1e6});
    progress.secondsLeft(1.0, 1 * kQuarter);
    // Region 1 was expected to take 1 s and has had 5: the two after it are
    // taken at the pace of 6 s for two regions at least.
    const double left = progress.secondsLeft(6.0, 1.5 * kQuarter);
    EXPECT_GE(left, 6.0);
    EXPECT_LT(left, 7.0);
}

TEST(ProgressTimeLeft, RegionsTheProbeTimedAtNothingGiveAFiniteTimeLeft) {
    Progress progress(false);
    // A tiny first region can take no measurable time.
    progress.expectCost({0, 1, 1, 1}, {1e3, 1e6, 1e6, 1e6});
    const double left = progress.secondsLeft(0.5, 0.1);
    EXPECT_TRUE(std::isfinite(left));
    EXPECT_GE(left, 0.0);
}

TEST(ProgressTimeLeft, NothingLeftWhenEveryRegionIsDone) {
    Progress progress(false);
    progress.expectCost({1, 2}, {1e6, 2e6});
    EXPECT_DOUBLE_EQ(progress.secondsLeft(3.0, 1.0), 0.0);
}

}  // namespace
