#!/usr/bin/env bash
# Which Vulkan drivers the GPU tests ran on, said out loud: the system's, and
# the second lavapipe (Debian 12's stock Mesa beside Mesa 25) when the build
# has one. Under CI (CI=true, and REQUIRE_BOTH=1: the release run) both must
# be there and differ: the suite supports both and must test both.
set -u
: "${SNELL:?}"
second=${SECOND_ICD:-}
first=$("$SNELL" --version | sed -n 's/^device: //p')
echo "drivers: system: ${first:-none}"
[ -n "$first" ] && [ "${first#none}" = "$first" ] || { echo "FAIL: no Vulkan device on the system driver"; exit 1; }
if [ -z "$second" ]; then
  echo "drivers: no second lavapipe (scripts/setup.sh unpacks one on Debian 12 unless SNELL_LAVAPIPE=stock)"
  if [ "${CI:-}" = true ] && [ "${REQUIRE_BOTH:-1}" = 1 ]; then echo "FAIL: CI requires the GPU tests on both lavapipes"; exit 1; fi
  exit 0
fi
other=$(VK_DRIVER_FILES="$second" "$SNELL" --version | sed -n 's/^device: //p')
echo "drivers: second: ${other:-none} ($second)"
if [ -z "$other" ] || [ "${other#none}" != "$other" ] || [ "$other" = "$first" ]; then
  echo "FAIL: the second lavapipe is missing or the same driver as the system's"; exit 1
fi
