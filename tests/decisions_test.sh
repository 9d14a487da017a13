#!/usr/bin/env bash
# Decisions that rounding can flip (render/Margins.h), one scene a kind:
# scenes/hard/decide-*.scn put a decision of every kind (nearest hit, hit or
# miss, inside or outside, total internal reflection, a shadow blocked)
# within float32's rounding but 1e-9 clear in double, in a ring of pixels at
# 32x32. In every pixel the GPU's render lies within its stated bound and the
# CPU reference's of the reference (tests/stated_bound.py), and the GPU says
# it traced pixels again in double; the decision mask marks them. A cut-off
# by weight is decided either way within the bound (a ray not traced leaves
# its weight times R in it): the CPU reference's bound covers the rounding of
# its weights and sums, so even a pixel whose tree ended states one above 0.
# shellcheck source=tests/cli_test_support.sh
source "$(dirname "$0")/cli_test_support.sh"
: "${PYTHON:=python3}"

for scene in "$SCENES"/hard/decide-*.scn; do
  name=$(basename "$scene" .scn)
  if "$PYTHON" "$(dirname "$0")/stated_bound.py" --snell "$SNELL" --size 32 "$scene" >"$work/out" 2>&1; then ok
  else bad "$name: a pixel beyond the stated bounds: $(grep -v '^$' "$work/out" | head -3)"; fi
  "$SNELL" render "$scene" --size 32 -o "$work/$name.pfm" --decision-mask "$work/$name-mask.pfm" --stats -q \
    >"$work/stats" 2>"$work/err"
  retraced=$(grep -o '"retraced_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
  undecided=$(grep -o '"undecided_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
  # Found: traced again in double, or where even that cannot settle it (a
  # pixel that only estimates its error), its bound widened.
  [ $((${retraced:-0} + ${undecided:-0})) -gt 0 ] && ok ||
    bad "$name: no decision found undecided: $(cat "$work/stats" "$work/err")"
  "$PYTHON" - "$work/$name-mask.pfm" "${retraced:-0}" "${undecided:-0}" <<'PY' && ok ||
import struct, sys
with open(sys.argv[1], 'rb') as f:
    f.readline(); f.readline(); f.readline()
    values = f.read()
marked = sum(1 for i in range(0, len(values) // 4, 3) if struct.unpack_from('<f', values, 4 * i)[0] > 0.0)
sys.exit(0 if marked >= max(int(sys.argv[2]), int(sys.argv[3])) and marked > 0 else 1)
PY
    bad "$name: the decision mask does not mark the pixels found undecided"
done

# Clear decisions stay decided: a ray that misses everything by far has no
# rival, whatever a flat ellipsoid's frame does to distances (an ellipsoid's
# "none" once became finite through its frame's scale, and every such ray
# undecided). Only pixels near a silhouette may be found undecided.
cat >"$work/flat.scn" <<'SCN'
view 32 0.5
light 1 1 1 -3 5 2
material 0.6 0.6 0.5 0.3 0.3 0.3 10
group
move -0.6 0 -4
scale 1 1 0.05
rotate 60 1 0 0
sphere
groupend
group
move 0.8 0 -4
scale 0.4 0.4 0.4
sphere
groupend
SCN
"$SNELL" render "$work/flat.scn" -o "$work/flat.pfm" --stats -q >"$work/stats" 2>"$work/err"
retraced=$(grep -o '"retraced_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
undecided=$(grep -o '"undecided_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
[ -n "$retraced" ] && [ $((retraced + ${undecided:-0})) -le 64 ] && ok ||
  bad "flat ellipsoid: ${retraced:-?} re-traced and ${undecided:-?} widened of 1024 pixels, most far from any edge"

# Where R is infinite, an undecided pixel has no bound but the clamp, on
# either side of its colour: in becker-1n (a gain of 1.5 traps light) the
# float tree of pixel (119, 56) at 128² grows an orbit to white where the
# exact light is mostly blue, and its bound must say up to 1, not 1 − its
# largest channel (0; nothing else covered it once a covered ray's shading
# stopped adding its rounding).
course="$SCENES/../../shared/course-scenes/becker-1n.scn"
if "$PYTHON" "$(dirname "$0")/stated_bound.py" --snell "$SNELL" --size 128 "$course" >"$work/out" 2>&1; then ok
else bad "becker-1n at 128²: a pixel beyond the stated bounds: $(grep -v '^$' "$work/out" | tail -3)"; fi

# SPEC §6 clamps: where a pixel stays white however its undecided decisions
# and rounding went (its colour less the light that hangs on them still at
# least 1 in every channel), they cannot reach the output. decide-shadow's
# wall made white by its ambient term alone: its ring's shadow rays are as
# undecided as there, yet no pixel is re-traced or widened, on the GPU or the
# CPU reference, and every pixel lies within its stated bound.
sed -e 's/^ambient 0.1 0.1 0.1/ambient 1.5 1.5 1.5/' "$SCENES/hard/decide-shadow.scn" >"$work/white.scn"
if "$PYTHON" "$(dirname "$0")/stated_bound.py" --snell "$SNELL" --size 32 "$work/white.scn" >"$work/out" 2>&1; then ok
else bad "white either way: a pixel beyond the stated bounds: $(grep -v '^$' "$work/out" | head -3)"; fi
for backend in "" --cpu; do
  "$SNELL" render "$work/white.scn" $backend --size 32 -o "$work/white.pfm" --stats -q >"$work/stats" 2>"$work/err"
  retraced=$(grep -o '"retraced_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
  undecided=$(grep -o '"undecided_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
  [ "${retraced:-0}" -eq 0 ] && [ -n "$undecided" ] && [ "$undecided" -eq 0 ] && ok ||
    bad "white either way (${backend:-gpu}): ${retraced:-?} re-traced, ${undecided:-?} widened: $(cat "$work/err")"
done

# A supersampled pixel re-traces only its samples whose light hangs on an
# undecided decision (SlotState::flagged): decide-nearest at 4 × 4 samples,
# where the disc's edge pixels hold samples on both sides of it. Fewer samples
# than all of the re-traced pixels' are traced again, some are, and every
# pixel lies within its stated bound.
"$SNELL" render "$SCENES/hard/decide-nearest.scn" --spp 4 --size 32 -o "$work/spp.pfm" --stats -q \
  >"$work/stats" 2>"$work/err"
retraced=$(grep -o '"retraced_pixels": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
samples=$(grep -o '"retraced_samples": [0-9]*' "$work/stats" | grep -o '[0-9]*$')
[ -n "$samples" ] && [ "$samples" -gt 0 ] && [ "$samples" -lt $((16 * ${retraced:-0})) ] && ok ||
  bad "per-sample re-trace: ${samples:-?} samples of ${retraced:-?} pixels re-traced: $(cat "$work/err")"
if "$PYTHON" "$(dirname "$0")/stated_bound.py" --snell "$SNELL" --size 32 --gpu-args "--spp 4" --cpu-args "--spp 4" \
  "$SCENES/hard/decide-nearest.scn" >"$work/out" 2>&1; then ok
else bad "per-sample re-trace: a pixel beyond the stated bounds: $(grep -v '^$' "$work/out" | head -3)"; fi

# The CPU reference's bound covers its own rounding: basic.scn's trees end
# (no light is left untraced), yet its pixels sum rounded terms, so none
# states a bound of 0, nor more than rounding.
"$SNELL" render "$SCENES/basic.scn" --cpu --size 16 -o "$work/m.pfm" --stats -q \
  >"$work/stats" 2>&1
mean=$(grep -o '"mean_bound": [0-9.e+-]*' "$work/stats" | grep -o '[0-9.e+-]*$')
"$PYTHON" -c "import sys; sys.exit(0 if 0 < float('$mean') < 1e-9 else 1)" && ok ||
  bad "the CPU reference's bound is not its rounding (mean bound ${mean:-none})"

echo "decisions: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
