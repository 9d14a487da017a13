#!/usr/bin/env bash
# Quick start 2: set up, build, and run the whole test suite (ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# The Khronos validation layer watches the GPU tests; any message fails them.
export SNELL_VALIDATION=1
(cd build && ctest --output-on-failure --timeout 900 "$@")

# The same suite built with AddressSanitizer and UndefinedBehaviorSanitizer
# (but for the limits: 4 000 000 spheres under ASan take minutes and tell
# nothing the release run does not).
cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSNELL_SANITIZE=ON >/dev/null
cmake --build build-sanitize --parallel
(cd build-sanitize && ctest --output-on-failure --timeout 900 -LE limits "$@")

# Short libFuzzer runs of the parser and of parser + CPU renderer.
bash tests/fuzz_test.sh
