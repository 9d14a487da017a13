#!/usr/bin/env bash
# Which Vulkan drivers the GPU tests ran on, said out loud: the system's, and
# the second lavapipe (Debian 12's stock Mesa beside Mesa 25) when the build
# has one. Where both are asked for (REQUIRE_BOTH=1: the release build) they
# must be there and differ: the suite supports both and must test both.
# Without a second lavapipe this test cannot test that: it is skipped
# (exit 77, ctest's SKIP_RETURN_CODE) saying why, and fails under CI
# (CI=true). The sanitized build asks for the system's alone
# (REQUIRE_BOTH=0), and tests that.
set -u
: "${SNELL:?}"
second=${SECOND_ICD:-}
first=$("$SNELL" --version | sed -n 's/^device: //p')
echo "drivers: system: ${first:-none}"
[ -n "$first" ] && [ "${first#none}" = "$first" ] || { echo "FAIL: no Vulkan device on the system driver"; exit 1; }
if [ -z "$second" ]; then
  if [ "${REQUIRE_BOTH:-1}" != 1 ]; then
    echo "drivers: the system's alone, as this build asks (REQUIRE_BOTH=0)"
    exit 0
  fi
  echo "drivers: no second lavapipe (SNELL_SECOND_LAVAPIPE_ICD; scripts/setup.sh unpacks one on Debian 12 unless SNELL_LAVAPIPE=stock)"
  if [ "${CI:-}" = true ]; then echo "FAIL: CI requires the GPU tests on both lavapipes"; exit 1; fi
  echo "SKIPPED: the GPU tests ran on one driver only; this test cannot check the second"
  exit 77
fi
other=$(VK_DRIVER_FILES="$second" "$SNELL" --version | sed -n 's/^device: //p')
echo "drivers: second: ${other:-none} ($second)"
if [ -z "$other" ] || [ "${other#none}" != "$other" ] || [ "$other" = "$first" ]; then
  echo "FAIL: the second lavapipe is missing or the same driver as the system's"; exit 1
fi
