// Wall-clock timing in milliseconds, as every timing snell reports is given.
#pragma once

#include <chrono>

namespace snell {

using Clock = std::chrono::steady_clock;

inline double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace snell
