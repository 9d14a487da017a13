// The time a tile's workgroups have left (render/WorkgroupSchedule), as a
// device with a few executors runs them: given, not measured, so exact.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "render/WorkgroupSchedule.h"

using snell::scheduleSecondsLeft;
using snell::spreadingStride;
using snell::WorkgroupWork;

namespace {

TEST(WorkgroupSchedule, WithoutAPaceShownItDoesNotGuess) {
    const std::vector<WorkgroupWork> none{{0, 5, 0}, {0, 5, 0}};
    EXPECT_LT(scheduleSecondsLeft(none, 2), 0.0);
}

TEST(WorkgroupSchedule, TwoExecutorsShareTheWorkgroupsLeft) {
    // Two ran for 2 s and did 1 each: 2 s a unit. Left: 1 + 1 running, then 1 + 1 waiting.
    const std::vector<WorkgroupWork> work{{1, 2, 2}, {1, 2, 2}, {0, 1, 0}, {0, 1, 0}};
    EXPECT_DOUBLE_EQ(scheduleSecondsLeft(work, 2), 4.0);
}

TEST(WorkgroupSchedule, AnOddWorkgroupOutAtTheEndRunsAlone) {
    // Three equal workgroups on two executors: the third runs alone after the
    // first two, so the tile takes 2 units' time, not 1.5.
    const std::vector<WorkgroupWork> work{{0.5, 1, 1}, {0.5, 1, 1}, {0, 1, 0}};
    EXPECT_DOUBLE_EQ(scheduleSecondsLeft(work, 2), 3.0);
}

TEST(WorkgroupSchedule, TheNextWorkgroupGoesToTheExecutorThatFreesFirst) {
    // Pace 1 s a unit. One has 3 units left, one 1: the waiting one (2
    // units) starts at 1 s and ends at 3 s, with the first.
    const std::vector<WorkgroupWork> work{{1, 4, 1}, {1, 2, 1}, {0, 2, 0}};
    EXPECT_DOUBLE_EQ(scheduleSecondsLeft(work, 2), 3.0);
}

TEST(WorkgroupSchedule, FinishedWorkgroupsSetThePaceAndNothingElse) {
    // One finished 4 units in 2 s; the running one has 1 unit left: 0.5 s.
    const std::vector<WorkgroupWork> work{{4, 4, 2}, {1, 2, 0.5}};
    EXPECT_DOUBLE_EQ(scheduleSecondsLeft(work, 2), 0.5);
}

TEST(WorkgroupSchedule, AllAtOnceTheTileEndsWithItsLongestWorkgroup) {
    // A GPU runs every workgroup at once: the tile ends with the one with most left.
    const std::vector<WorkgroupWork> work{{1, 3, 1}, {1, 2, 1}, {1, 5, 1}};
    EXPECT_DOUBLE_EQ(scheduleSecondsLeft(work, 3), 4.0);
}

TEST(WorkgroupSchedule, NeighbouringWorkgroupsTakeSharesApart) {
    // Where one thread runs the first half of the workgroups and another the
    // rest, each takes shares from both halves of the tile (with the share
    // its own index, the first thread took the left half of a 1024-wide tile).
    for (std::uint32_t count = 1; count <= 600; ++count) {
        SCOPED_TRACE(count);
        const std::uint32_t stride = spreadingStride(count);
        std::vector<bool> taken(count, false);
        std::uint32_t firstHalfInLeftHalf = 0;
        for (std::uint32_t g = 0; g < count; ++g) {
            const std::uint32_t share = std::uint32_t(std::uint64_t(g) * stride % count);
            EXPECT_FALSE(taken[share]);
            taken[share] = true;
            if (g < count / 2 && 2 * share < count) ++firstHalfInLeftHalf;
        }
        if (count >= 8) {
            EXPECT_GE(4 * firstHalfInLeftHalf, count / 2);
            EXPECT_LE(4 * firstHalfInLeftHalf, 3 * (count / 2));
        }
    }
}

}  // namespace
