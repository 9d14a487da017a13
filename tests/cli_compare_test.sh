#!/usr/bin/env bash
# What a render says of its truncation, taken at its word: each warning's
# advice is followed and the warning must go, tracing no more rays than the
# tree it replaces where that is the promise; compare with a reference's bound
# image on every stock scene, and what it refuses to read as one; `snell
# assemble` refusing pieces that overlap or come from different renders, by
# name.
#   SNELL=$PWD/build/snell SCENES=$PWD/scenes bash tests/cli_compare_test.sh
# shellcheck source=tests/cli_test_support.sh
source "$(dirname "$0")/cli_test_support.sh"

# render SCENE ARGS...: renders at 32² with --stats; stderr in $work/err, the
# rays traced in $rays.
render() {
  local scene=$1
  shift
  "$SNELL" render "$SCENES/$scene" --size 32 -o "$work/r.pfm" --stats "$@" >"$work/stats" 2>"$work/err" || return 1
  rays=$(tail -n 1 "$work/stats" | python3 -c 'import json, sys; print(json.loads(sys.stdin.read())["rays"]["total"])')
}
# advice PATTERN: the options quoted in the warning that matches PATTERN.
advice() { grep "snell: warning: .*$1" "$work/err" | grep -o "'--[^']*'" | head -n 1 | tr -d "'"; }
# follow ARGS... -- ADVICE: ARGS with the advice's options in place of those of the same names.
follow() {
  python3 - "$@" <<'PY'
import sys
args = sys.argv[1:]
cut = args.index("--")
given, advice = args[:cut], " ".join(args[cut + 1:]).split()
named = {advice[i] for i in range(0, len(advice), 2)}
out, i = [], 0
while i < len(given):
    if given[i] in named:
        i += 2
        continue
    out.append(given[i])
    i += 1
print(" ".join(out + advice))
PY
}
# check_advice NAME SCENE PATTERN [fewer] ARGS...: the render of ARGS warns
# PATTERN with advice; ARGS with the advice do not warn so, and with `fewer`
# trace no more rays. The rays of both are reported.
check_advice() {
  local name=$1 scene=$2 pattern=$3 fewer=$4
  shift 4
  render "$scene" "$@" && grep -q "snell: warning: .*$pattern" "$work/err" || { bad "$name: no warning: $(cat "$work/err")"; return; }
  local given=$rays tip
  tip=$(advice "$pattern")
  [ -n "$tip" ] || { bad "$name: the warning gives no options to take: $(cat "$work/err")"; return; }
  # shellcheck disable=SC2046
  render "$scene" $(follow "$@" -- "$tip") || { bad "$name: '$tip' failed: $(cat "$work/err")"; return; }
  echo "$name: $given rays; with '$tip', $rays"
  ! grep -q "snell: warning: .*$pattern" "$work/err" || { bad "$name: '$tip' left the warning: $(cat "$work/err")"; return; }
  [ "$fewer" != fewer ] || [ "$rays" -le "$given" ] || { bad "$name: '$tip' traced $rays rays, more than $given"; return; }
  ok
}

T=0.00196078
# The default's pixels with no finite bound whose estimate had not settled at
# the floor: a lower floor with the same tolerance settles them.
check_advice "default" glass.scn "estimated error was not yet within the tolerance" more
# A fixed tree's: a tolerance with the same floor estimates them, tracing no
# more than the fixed tree (glass.scn has no trap: nothing goes below the floor).
check_advice "fixed tree" glass.scn "a fixed tree .* does not estimate" fewer --min-weight 1e-7
check_advice "depth 5, no cut-off" glass.scn "a fixed tree .* does not estimate" fewer --cpu --depth 5 --min-weight 0
# A tolerance capped by --depth: a deeper cap (the CPU reference says the same).
check_advice "depth cap" glass.scn "reached the depth limit 5" more --cpu --depth 5 --min-weight 0 --tolerance $T
# Pixels with a finite bound above a tight tolerance at the floor: a lower floor.
check_advice "bounded" mirrors.scn "may still be further than the tolerance 1e-06" more --tolerance 1e-6
# The reference's own: a lower floor.
check_advice "reference" glass.scn "estimated error was not yet within the tolerance" more --cpu
# No floor: trees that need not end stop at the budget; a floor ends them.
check_advice "no floor" glass.scn "reached the tree budget of 4096" fewer --min-weight 0 --tree-budget 4096
# With a floor: a larger budget.
check_advice "budget" glass.scn "reached the tree budget of 128" more --tree-budget 128
render glass.scn --min-weight 0 --tree-budget 4096
! grep -q "a lower --min-weight" "$work/err" && ok || bad "--min-weight 0 told to lower it: $(cat "$work/err")"
# Estimated pixels are said to be estimated, not bounded, when nothing else is wrong.
render showcase.scn && grep -q "snell: note: [0-9]* pixel(s) have no finite error bound.*an estimate, not a bound" "$work/err" &&
  ! grep -q "warning" "$work/err" && ok || bad "no note of estimated pixels: $(cat "$work/err")"

# The bound-image recipe on every stock scene (GPU against the CPU reference):
# pixels the reference only estimates are held to their estimates, none left
# out; the bound image as EXR and as PFM.
for file in "$SCENES"/*.scn; do
  name=$(basename "$file" .scn)
  ext=exr
  [ "$name" != glass ] || ext=pfm
  "$SNELL" render "$file" --size 24 -q -o "$work/$name.exr" &&
    "$SNELL" render "$file" --size 24 -q --cpu -o "$work/$name-exact.exr" --bound-image "$work/$name-bound.$ext" &&
    "$SNELL" compare "$work/$name.exr" "$work/$name-exact.exr" --bound-image "$work/$name-bound.$ext" >"$work/out" &&
    grep -q "^left out 0 uncertain" "$work/out" && ok || bad "bound-image recipe on $name: $(cat "$work/out")"
done
"$SNELL" compare "$work/glass.exr" "$work/glass-exact.exr" --bound-image "$work/glass-bound.pfm" |
  grep -q "^held [1-9][0-9]* of them to the reference's estimated error" && ok || bad "no pixel of glass held to an estimate"
# Held to their estimates: a far shallower render is bad there, not left out.
"$SNELL" render "$SCENES/glass.scn" --size 24 -q --depth 1 -o "$work/shallow.exr" &&
  "$SNELL" compare "$work/shallow.exr" "$work/glass-exact.exr" --bound-image "$work/glass-bound.pfm" --json >"$work/out"
python3 - "$work/out" <<'PY' && ok || bad "estimated pixels not held to their estimates: $(cat "$work/out")"
import json, sys
m = json.load(open(sys.argv[1]))
assert m["estimated_bad_pixels"] > 0 and m["uncertain_pixels"] == 0 and not m["agree"], m
PY
# A colour image is no bound image: refused by name, status 2.
for colour in showcase.exr showcase-exact.exr; do
  "$SNELL" compare "$work/showcase.exr" "$work/showcase-exact.exr" --bound-image "$work/$colour" >"$work/out" 2>"$work/err"
  status=$?
  [ $status -eq 2 ] && grep -q "snell: error: '$work/$colour' is a render of .*, not a bound image" "$work/err" && ok ||
    bad "colour image $colour taken for a bound image ($status): $(cat "$work/out" "$work/err")"
done
"$SNELL" render "$SCENES/showcase.scn" --size 24 -q -o "$work/showcase.pfm"
"$SNELL" compare "$work/showcase.exr" "$work/showcase-exact.exr" --bound-image "$work/showcase.pfm" 2>"$work/err"
[ $? -eq 2 ] && grep -q "is a colour image (its channels differ), not a bound image" "$work/err" && ok ||
  bad "colour PFM taken for a bound image: $(cat "$work/err")"
# An earlier snell's bound image (RGB, equal channels) is read with a note;
# one that leaves every pixel out compares nothing, and that never agrees.
python3 - "$work/old-bound.pfm" <<'PY'
import struct, sys
with open(sys.argv[1], "wb") as f:
    f.write(b"PF\n24 24\n-1.0\n" + struct.pack("<f", 1.0) * (24 * 24 * 3))
PY
"$SNELL" compare "$work/showcase.exr" "$work/showcase-exact.exr" --bound-image "$work/old-bound.pfm" \
  --max-uncertain 100 >"$work/out" 2>"$work/err"; status=$?
[ $status -eq 1 ] && grep -q "^differ: no pixel compared" "$work/out" && ! grep -q "PSNR inf" "$work/out" &&
  grep -q "snell: warning: .* has no bound-image marker" "$work/err" && ok ||
  bad "comparing nothing ($status): $(cat "$work/out" "$work/err")"

# assemble: pieces that overlap, of renders of other sizes or scenes, or
# placed where their region was not, are refused by name; nothing is written.
refused() {  # refused NAME PATTERN PIECES...
  local name=$1 pattern=$2
  shift 2
  "$SNELL" assemble -o "$work/joined.png" "$@" 2>"$work/err"; local status=$?
  [ $status -eq 2 ] && [ ! -e "$work/joined.png" ] && grep -q "snell: error: .*$pattern" "$work/err" && ok ||
    bad "assemble $name ($status): $(cat "$work/err")"
}
a="$SCENES/basic.scn"
"$SNELL" render "$a" --size 32 -q -o "$work/w1.png" && "$SNELL" render "$a" --size 32 -q -o "$work/w2.png" &&
  "$SNELL" render "$a" --size 32 -q --region 0 0 32 16 -o "$work/top.png" &&
  "$SNELL" render "$a" --size 32 -q --region 0 16 32 32 -o "$work/bottom.png" &&
  "$SNELL" render "$a" --size 16 -q --region 0 8 16 16 -o "$work/bottom16.png" &&
  "$SNELL" render "$a" --size 32 -q --region 0 0 32 16 -o "$work/top.exr" &&
  "$SNELL" render "$a" --size 16 -q --region 0 8 16 16 -o "$work/bottom16.exr" &&
  "$SNELL" render "$SCENES/showcase.scn" --size 32 -q --region 0 16 32 32 -o "$work/other.png" || bad "pieces"
refused "overlapping" "pieces '$work/w1.png' at 0,0 and '$work/w2.png' at 20,0 .* overlap in 12x32 pixels from 20,0" \
  0,0:"$work/w1.png" 20,0:"$work/w2.png"
refused "of a 32² and a 16² render" "'$work/top.png' is a piece of a 32x32 render and '$work/bottom16.png' of a 16x16 one" \
  0,0:"$work/top.png" 0,8:"$work/bottom16.png"
refused "EXR of a 32² and a 16² render" "'$work/top.exr' is a piece of a 32x32 render and '$work/bottom16.exr' of a 16x16" \
  "$work/top.exr" "$work/bottom16.exr"
refused "misplaced" "'$work/bottom.png' is the piece at 0,16 of its render, but is placed at 0,20" \
  0,0:"$work/top.png" 0,20:"$work/bottom.png"
refused "of other scenes" "'$work/top.png' and '$work/other.png' are pieces of different renders (scene " \
  0,0:"$work/top.png" 0,16:"$work/other.png"
refused "--size" "'$work/top.png' is a piece of a 32x32 render, not of --size 40" -s 40 0,0:"$work/top.png" 0,16:"$work/bottom.png"
# A piece alone: the size its file records says what is missing.
refused "missing" "leave 512 of the 32x32 pixels uncovered, the first at 0,16" 0,0:"$work/top.png"
# Pieces that belong together still join, bit for bit.
"$SNELL" assemble -o "$work/joined.png" 0,16:"$work/bottom.png" 0,0:"$work/top.png" &&
  "$SNELL" compare "$work/joined.png" "$work/w1.png" --max-mean 0 --max-bad 0 >/dev/null && ok || bad "PNG pieces no longer join"

echo "cli (truncation, compare, assemble): $pass passed, $fail failed"
[ $fail -eq 0 ]
