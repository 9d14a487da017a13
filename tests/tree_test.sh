#!/usr/bin/env bash
# What the trace settings ask for, read from --stats ray counts and images
# (never from timings):
# * a depth or a cut-off without --tolerance is one fixed tree, traced once,
#   the same as with --tolerance 0 (each kind of tree on some of the scenes);
# * under a tolerance no ray is traced twice: each camera ray once, however
#   many cut-off steps a pixel takes;
# * a looser tolerance never traces more rays;
# * a diverging pixel (light trapped in an amplifying material) comes out
#   saturated, as the limit reference has it;
# * where R is infinite but each ray's reach is not (render/Reach.h: glass of
#   ks + kt = 1 beside a mirror), every pixel states a finite bound.
# TREE_PART=K/N runs the K-th of N parts (scenes dealt round; the diverging
# scene in the first), so the parts run side by side; by default all of it.
set -u
: "${SNELL:?}" "${SOURCE:?}" "${SHARED:?}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }

# rays SCENE SIZE OUT ARGS...: prints "total primary" from --stats.
rays() {
  local scene=$1 size=$2 out=$3
  shift 3
  "$SNELL" render "$scene" --size "$size" -q --stats -o "$out" "$@" | tail -n 1 |
    python3 -c 'import json, sys; d = json.loads(sys.stdin.read())["rays"]; print(d["total"], d["primary"])'
}
same_image() { cmp -s "$1" "$2"; }

scenes=("$SHARED/bench-scenes/glass.scn" "$SHARED/bench-scenes/simple.scn" "$SHARED/bench-scenes/grid.scn"
        "$SOURCE/scenes/showcase.scn" "$SOURCE/scenes/glass.scn" "$SOURCE/scenes/hard/light-between-mirrors.scn"
        "$SHARED/course-scenes/becker-1n.scn" "$SHARED/course-scenes/becker-SphereFlake2.scn")
size=24
part=${TREE_PART:-1/1}
k=${part%/*} n=${part#*/}
[ "$k" -ge 1 ] && [ "$k" -le "$n" ] 2>/dev/null || { echo "FAIL: TREE_PART=$part is not K/N"; exit 1; }
mine=()
for i in "${!scenes[@]}"; do [ $((i % n + 1)) -eq "$k" ] && mine+=("${scenes[$i]}"); done
scene_index() { local i; for i in "${!scenes[@]}"; do [ "${scenes[$i]}" = "$1" ] && echo "$i"; done; }

for scene in "${mine[@]}"; do
  name=$(basename "$scene" .scn)
  spp=$(awk '$1 == "supersample" {print $2}' "$scene" | tail -n 1)
  pixels=$((size * size * ${spp:-1} * ${spp:-1}))

  # A fixed tree: --depth / --min-weight alone trace it once, as --tolerance 0
  # does. Each setting is its own kernel, compiled for each scene (seconds on
  # lavapipe), so the three kinds of tree are dealt round the scenes.
  fixed_settings=("--depth 5 --min-weight 0" "--min-weight 0.001" "--depth 3")
  fixed=${fixed_settings[$(($(scene_index "$scene") % 3))]}
  # shellcheck disable=SC2086
  alone=$(rays "$scene" $size "$work/a.pfm" $fixed)
  # shellcheck disable=SC2086
  zero=$(rays "$scene" $size "$work/z.pfm" $fixed --tolerance 0)
  [ "$alone" = "$zero" ] && same_image "$work/a.pfm" "$work/z.pfm" && ok ||
    bad "$name: '$fixed' traced '$alone' rays, with --tolerance 0 '$zero' (or another image)"
  [ "${alone#* }" = "$pixels" ] && ok || bad "$name: '$fixed' traced ${alone#* } camera rays for $pixels samples"

  # Under tolerances, looser to tighter: each camera ray once, and never more
  # rays for a looser tolerance.
  previous=0
  for tolerance in 0.0314 0.0078 0.00196 0.0004; do
    counts=$(rays "$scene" $size "$work/t.pfm" --tolerance "$tolerance")
    total=${counts% *}
    [ "${counts#* }" = "$pixels" ] && ok || bad "$name: --tolerance $tolerance traced ${counts#* } camera rays for $pixels samples"
    [ "$total" -ge "$previous" ] && ok || bad "$name: --tolerance $tolerance traced $total rays, a looser one $previous"
    previous=$total
  done
done

# Light trapped in a sphere of ks + kt > 1 diverges, and the pixel saturates:
# the default render agrees with the limit reference there (8-bit values).
if [ "$k" -eq 1 ]; then
  scene="$SOURCE/scenes/hard/glass-in-water-gap-0.scn"
  "$SNELL" render "$scene" --size 48 -q -o "$work/gpu.png" && "$SNELL" render "$scene" --size 48 --cpu -q -o "$work/ref.png" &&
    { "$SNELL" compare "$work/gpu.png" "$work/ref.png" --json >"$work/cmp"; [ $? -le 1 ]; } && ok ||
    bad "diverging scene did not render"
  python3 - "$work/cmp" <<'EOF' && ok || bad "diverging pixels differ from the limit reference: $(cat "$work/cmp")"
import json, sys
m = json.load(open(sys.argv[1]))
sys.exit(0 if m["bad_pixels"] <= 2 else 1)
EOF
fi

# Each ray's reach: no pixel of the glass beside a mirror is left unbounded
# or on an estimate, on the GPU or on the CPU.
if [ "$k" -eq 1 ]; then
  for backend in "" --cpu; do
    "$SNELL" render "$SOURCE/scenes/hard/glass-beside-mirror.scn" $backend --size 32 -q --stats \
      -o "$work/reach.pfm" >"$work/stats" 2>"$work/err" || bad "glass beside a mirror ($backend) did not render"
    unbounded=$(grep -o '"unbounded_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
    estimated=$(grep -o '"estimated_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
    [ "${unbounded:-x}" = 0 ] && [ "${estimated:-x}" = 0 ] && ok ||
      bad "glass beside a mirror ($backend): $unbounded unbounded, $estimated estimated pixels"
  done
fi

echo "tree tests ($part: ${#mine[@]} scenes): $pass passed, $fail failed"
[ "$fail" -eq 0 ]
