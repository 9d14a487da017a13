#!/usr/bin/env bash
# Quick start 2: set up, build, and run the whole test suite (ctest), as CI
# does: the release build's suite, then the sanitized build's (host code under
# AddressSanitizer and UndefinedBehaviorSanitizer, and the fuzz targets).
# docs/testing.md lists the tests and what each takes. Tests run side by side,
# one a core (SNELL_TEST_JOBS to change); those that measure memory run alone.
# Arguments go to both ctest runs (e.g. -R cli).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# The Khronos validation layer watches the GPU tests; any message fails them.
export SNELL_VALIDATION=1
jobs=${SNELL_TEST_JOBS:-$(nproc)}
(cd build && ctest --output-on-failure --timeout 300 -j "$jobs" "$@")

# The sanitized build, by clang so it also has the libFuzzer targets: its
# unit tests, the command line on good and bad input, a GPU smoke selection
# and 30 s of fuzzing a target (tests/CMakeLists.txt). ccache where present.
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
CC=clang-14 CXX=clang++-14 cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSNELL_SANITIZE=ON \
  "${launcher[@]}" >/dev/null
cmake --build build-sanitize --parallel
(cd build-sanitize && ctest --output-on-failure --timeout 300 -j "$jobs" "$@")
