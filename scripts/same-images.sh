#!/usr/bin/env bash
# Whether two builds of snell render the same images, bit for bit: every
# scene of scenes/, scenes/hard/, the course and the bench, at the defaults,
# at a fixed tree (--depth 5 --min-weight 0) and at --precision fp64, colour
# and bound as PFM, on the system's lavapipe and, where scripts/setup.sh
# unpacked it, the second one. For a change that must not change behaviour
# (a refactoring of the kernel): keep a copy of the old binary first.
#
#   scripts/same-images.sh OLD_SNELL NEW_SNELL [SIZE]   (default size 128)
#
# Exit 0 when every image is the same. --precision fp64 under a loop budget
# (Mesa 22.3) is not reproducible from run to run even by one binary (a ray
# suspended between dispatches is stored as a float pair), so such a
# difference is checked against a second run of the old binary.
set -u
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n '2,13p' "$0" >&2; exit 2; }
old=$(realpath "$1") new=$(realpath "$2") size=${3:-128}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scenes=(scenes/*.scn scenes/hard/*.scn)
[ -d ../shared ] && scenes+=(../shared/course-scenes/*.scn ../shared/bench-scenes/*.scn)
drivers=(system)
second=$(ls build/lavapipe-*/lvp_icd.json 2>/dev/null | head -n 1)
[ -n "$second" ] && drivers+=("$second")

render() {  # render BINARY DRIVER SCENE SETTING OUT
  local args=()
  case $4 in fixed) args=(--depth 5 --min-weight 0) ;; fp64) args=(--precision fp64) ;; esac
  if [ "$2" = system ]; then
    "$1" render -q "$3" --size "$size" "${args[@]}" -o "$5.pfm" --bound-image "$5.bound.pfm" 2>/dev/null
  else
    VK_DRIVER_FILES=$2 "$1" render -q "$3" --size "$size" "${args[@]}" -o "$5.pfm" --bound-image "$5.bound.pfm" 2>/dev/null
  fi
}

same=0 differ=0 unsteady=0
for driver in "${drivers[@]}"; do
  for scene in "${scenes[@]}"; do
    for setting in default fixed fp64; do
      render "$old" "$driver" "$scene" "$setting" "$work/old" || { echo "old build failed: $scene $setting" >&2; exit 1; }
      render "$new" "$driver" "$scene" "$setting" "$work/new" || { echo "FAIL: $scene $setting ($driver): the new build failed"; differ=$((differ + 1)); continue; }
      if cmp -s "$work/old.pfm" "$work/new.pfm" && cmp -s "$work/old.bound.pfm" "$work/new.bound.pfm"; then
        same=$((same + 1))
        continue
      fi
      render "$old" "$driver" "$scene" "$setting" "$work/again"
      if ! cmp -s "$work/old.pfm" "$work/again.pfm" || ! cmp -s "$work/old.bound.pfm" "$work/again.bound.pfm"; then
        echo "unsteady: $scene $setting ($driver): the old build differs from itself"
        unsteady=$((unsteady + 1))
      else
        echo "FAIL: $scene $setting ($driver): the images differ"
        differ=$((differ + 1))
      fi
    done
  done
done
echo "same-images: $same same, $differ differ, $unsteady not reproducible by the old build"
[ "$differ" -eq 0 ]
