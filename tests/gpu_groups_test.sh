#!/usr/bin/env bash
# The GPU tests run as ctest groups, one process each (tests/CMakeLists.txt,
# snell_gpu_group): every test of the executable is in some group, so none
# is left out when a test is added or renamed. Lists tests, renders nothing.
# Usage: gpu_groups_test.sh SNELL_GPU_TESTS FILTER...
set -u
tests=${1:?}
shift
# --gtest_list_tests prints "Suite." then indented "  Name  # GetParam() = ...".
list() {
  "$tests" --gtest_list_tests "$@" | awk '/^[^ ]/ { suite = $1; next } { print suite $1 }'
}
all=$(list) || { echo "FAIL: $tests --gtest_list_tests"; exit 1; }
grouped=$(for filter in "$@"; do list --gtest_filter="$filter"; done | sort -u)
missing=$(comm -23 <(echo "$all" | sort -u) <(echo "$grouped"))
echo "gpu groups: $(echo "$all" | wc -l) tests, $# groups"
if [ -n "$missing" ]; then
  echo "FAIL: in no ctest group (tests/CMakeLists.txt, snell_gpu_group):"
  echo "$missing"
  exit 1
fi
