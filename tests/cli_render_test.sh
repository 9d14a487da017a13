#!/usr/bin/env bash
# The command line as a user meets it while rendering (the rest is
# tests/cli_test.sh): signals and a failing GPU leave no file, the stated
# bound, --region and `snell assemble`, the progress bar, runaway trees, -o -,
# check, standard input, compare, suggestions, warnings, --count-lanes.
# shellcheck source=tests/cli_test_support.sh
source "$(dirname "$0")/cli_test_support.sh"
# interrupt_after PATTERN ARGS...: `snell render ARGS` with its stderr in
# $work/err, interrupted once a line matches PATTERN (a warning printed before
# the render starts) or after 20 s; a second later, to let any warning that
# would follow it come out.
interrupt_after() {
  local pattern=$1 pid t
  shift
  "$SNELL" render "$@" 2>"$work/err" &
  pid=$!
  for ((t = 0; t < 200; t++)); do
    grep -q -- "$pattern" "$work/err" && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
  done
  sleep 1
  kill -INT $pid 2>/dev/null
  wait $pid
}
# A scene with an error at 3:9 (as in tests/cli_test.sh).
printf 'view 16 0.5\nsphere\nscale 1 0 1\n' >"$work/bad.scn"

# Ctrl-C, SIGTERM or SIGHUP during a long render (CPU and GPU): status 128 +
# the signal, no output file, no temporary left.
for sig in INT:130 TERM:143 HUP:129; do
  for device in --cpu ""; do
    # shellcheck disable=SC2086
    "$SNELL" render "$SCENES/showcase.scn" --size 4096 $device -o "$work/interrupted.png" 2>/dev/null &
    pid=$!
    sleep 1
    kill -"${sig%%:*}" $pid
    wait $pid; status=$?
    [ $status -eq "${sig##*:}" ] && [ ! -e "$work/interrupted.png" ] && ! ls "$work" | grep -q "interrupted.png.tmp" && ok ||
      bad "render ${device:-(GPU)} ended by SIG${sig%%:*} (status $status): $(ls "$work")"
  done
done

# A GPU that fails mid-render (simulated by the SNELL_INJECT_FAULT hook): the
# device is lost after the first band of rows has been streamed (1100² is 2x2
# tiles; submissions, with a cache of its own: the driver probe, the
# pipeline's first dispatch, then a dispatch a tile, so the 6th is the last
# tile's), or memory runs out while
# the render allocates its buffers. Status 1, a message saying what happened,
# the existing output untouched, no temporary left; the validation layer sees
# the cleanup and must stay silent.
for fault in device-lost:6 out-of-device-memory:9; do
  echo "precious" >"$work/fault.png"
  SNELL_CACHE_DIR="$work/cache-$fault" SNELL_INJECT_FAULT=$fault SNELL_VALIDATION=1 "$SNELL" render "$SCENES/basic.scn" --size 1100 -o "$work/fault.png" \
    2>"$work/err"; status=$?
  case $fault in device-lost*) want="device was lost";; *) want="ran out of memory";; esac
  [ $status -eq 1 ] && grep -q "$want" "$work/err" && grep -q "no image was written" "$work/err" &&
    ! grep -qi "validation" "$work/err" && [ "$(cat "$work/fault.png")" = "precious" ] &&
    ! ls "$work" | grep -q "fault.png." && ok || bad "$fault (status $status): $(cat "$work/err"; ls "$work")"
  rm -rf "$work/cache-$fault"
done
SNELL_INJECT_FAULT=cosmic-ray "$SNELL" render "$SCENES/basic.scn" -o "$work/x.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "unknown fault" "$work/err" && ok || bad "bad SNELL_INJECT_FAULT ($status)"

# -v says where the time went, on stderr only.
"$SNELL" render "$SCENES/basic.scn" --size 16 -o "$work/v.png" -v >"$work/out" 2>"$work/err" &&
  [ ! -s "$work/out" ] && grep -q "render .* ms (timed by the \(GPU\|host\)" "$work/err" && ok || bad "-v: $(cat "$work/err")"

# The truncation bound: in --stats, as an image, and --tolerance keeping it
# within T on both back ends (scenes/mirrors.scn: ks 0.9 corridors).
for backend in "" "--cpu"; do
  "$SNELL" render "$SCENES/mirrors.scn" --size 24 -q $backend --tolerance 0.00196 --min-weight 1e-9 \
    -o "$work/tol.pfm" --bound-image "$work/bound.pfm" --stats >"$work/stats" 2>"$work/err"; status=$?
  [ $status -eq 0 ] && [ -s "$work/bound.pfm" ] && tail -n 1 "$work/stats" | python3 -c '
import json, sys
t = json.loads(sys.stdin.read())["truncation"]
assert 0 <= t["max_bound"] <= 0.00196, t
assert t["mean_bound"] <= t["max_bound"] and t["unbounded_pixels"] == 0 and t["deepest_ray"] >= 1, t
' && ok || bad "--tolerance/--bound-image ${backend:-gpu} ($status): $(cat "$work/err")"
done
"$SNELL" render "$SCENES/mirrors.scn" --size 8 -q --tolerance -1 -o "$work/x.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && ok || bad "--tolerance -1 gave $status (want 2)"

# Renders split for a farm: --region windows joined by `snell assemble` are
# the whole render bit for bit, on both back ends; bad windows and missing
# pieces are errors (status 2) that write nothing.
for backend in "" "--cpu"; do
  "$SNELL" render "$SCENES/showcase.scn" --size 40 -q $backend -o "$work/whole.pfm" &&
  "$SNELL" render "$SCENES/showcase.scn" --size 40 -q $backend --region 0 0 25 17 -o "$work/p1.pfm" &&
  "$SNELL" render "$SCENES/showcase.scn" --size 40 -q $backend --region 25 0 40 17 -o "$work/p2.pfm" &&
  "$SNELL" render "$SCENES/showcase.scn" --size 40 -q $backend --region 0 17 40 40 -o "$work/p3.pfm" &&
  "$SNELL" assemble -s 40 -o "$work/joined.pfm" 0,0:"$work/p1.pfm" 25,0:"$work/p2.pfm" 0,17:"$work/p3.pfm" &&
  cmp -s "$work/whole.pfm" "$work/joined.pfm" && ok || bad "--region + assemble not bit-identical (${backend:-gpu})"
done
# EXR pieces carry their data window: no offsets needed, nor the size.
"$SNELL" render "$SCENES/showcase.scn" --size 40 -q -o "$work/whole-gpu.pfm" || bad "whole GPU render"
for w in "0 0 25 17:e1" "25 0 40 17:e2" "0 17 40 40:e3"; do
  "$SNELL" render "$SCENES/showcase.scn" --size 40 -q --region ${w%:*} -o "$work/${w#*:}.exr" || bad "EXR piece ${w#*:}"
done
"$SNELL" assemble -o "$work/joined-exr.pfm" "$work/e3.exr" "$work/e1.exr" "$work/e2.exr" &&
  cmp -s "$work/whole-gpu.pfm" "$work/joined-exr.pfm" && ok || bad "EXR pieces placed by their data windows not bit-identical"
"$SNELL" render "$SCENES/basic.scn" --size 16 -q --region 0 0 17 8 -o "$work/r.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && [ ! -e "$work/r.png" ] && grep -q "is not a window" "$work/err" && ok || bad "--region outside the image ($status)"
"$SNELL" assemble -s 40 -o "$work/j.png" 0,0:"$work/p1.pfm" 0,17:"$work/p3.pfm" 2>"$work/err"; status=$?
[ $status -eq 2 ] && [ ! -e "$work/j.png" ] && grep -q "uncovered" "$work/err" && ok || bad "assemble with a missing piece ($status)"
"$SNELL" assemble -o "$work/j.png" "$work/p1.pfm" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "X,Y:FILE" "$work/err" && ok || bad "assemble PFM piece without X,Y: ($status)"

# Progress: on a terminal a bar with elapsed time, estimate and rays/s, erased
# at the end; nothing of it when standard error is not a terminal.
if command -v script >/dev/null; then
  script -qfec "$SNELL render $SCENES/showcase.scn --size 200 --spp 2 -o $work/prog.png" "$work/tty" >/dev/null 2>&1
  grep -q "elapsed" "$work/tty" && grep -q "Mrays/s" "$work/tty" && [ -s "$work/prog.png" ] && ok ||
    bad "no progress bar on a terminal: $(tr '\r' '\n' <"$work/tty" | head -3)"
  # A render long enough for the bar to matter first estimates its rays from a
  # sparse render of the same image (--verbose says how long that took); one
  # it expects to be short keeps its tiles in blocks (interleaved tiles cost
  # a cheap scene more than its estimate gains).
  script -qfec "$SNELL render $SCENES/basic.scn --size 2048 -v -o $work/prog3.png" "$work/tty" >/dev/null 2>&1
  grep -q "time-left probe [0-9.]* ms" "$work/tty" && [ -s "$work/prog3.png" ] && ok || bad "no ray estimate for the progress bar"
  grep -q " 4 tiles, " "$work/tty" && ok || bad "a short render under the bar was not traced in 4 blocks: $(grep -a tiles "$work/tty")"
  # A longer one may go in interleaved tiles (as its probe expects it to
  # take): the image is the one rendered without the bar, whichever it is.
  script -qfec "$SNELL render $SCENES/glass.scn --size 1100 -v -o $work/prog4.png" "$work/tty" >/dev/null 2>&1
  "$SNELL" render "$SCENES/glass.scn" --size 1100 -q -o "$work/prog4-quiet.png" &&
    cmp -s "$work/prog4.png" "$work/prog4-quiet.png" && ok ||
    bad "the image under the progress bar differs ($(grep -a -o '[0-9]* [a-z ]*tiles' "$work/tty"))"
fi
"$SNELL" render "$SCENES/showcase.scn" --size 64 -o "$work/prog2.png" 2>"$work/err"; status=$?
[ $status -eq 0 ] && [ -s "$work/prog2.png" ] && ! grep -q "elapsed" "$work/err" && ok ||
  bad "progress written to a non-terminal, or the render failed ($status)"

# No runaway trees: settings that let an amplifying tree grow without bound
# are refused before tracing (status 2, naming the sphere's material and a
# setting that finishes), unless asked for explicitly.
"$SNELL" render "$SCENES/glass.scn" --size 8 --tree-budget 0 --min-weight 0 -o "$work/run.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && [ ! -e "$work/run.png" ] && grep -q "glass.scn:[0-9]*:[0-9]*: error: .*ks + kt = 1.05" "$work/err" &&
  grep -q -- "--tree-budget 65536" "$work/err" && grep -q -- "--allow-runaway" "$work/err" && ok ||
  bad "runaway tree not refused ($status): $(cat "$work/err")"
"$SNELL" render "$SCENES/glass.scn" --size 8 -q --tree-budget 0 --min-weight 0 --depth 4 --allow-runaway -o "$work/run.png" &&
  ok || bad "--allow-runaway"
"$SNELL" render "$SCENES/mirrors.scn" --size 8 -q --tree-budget 0 --min-weight 0 -o "$work/run.png" &&
  ok || bad "a chain of mirrors without cut-off is bounded by its depth and must render"

# -o - streams PPM to standard output (and --stats moves to standard error).
"$SNELL" render "$SCENES/basic.scn" --size 16 -o - -q --stats >"$work/pipe.ppm" 2>"$work/err"; status=$?
[ $status -eq 0 ] && [ "$(head -c 2 "$work/pipe.ppm")" = "P6" ] && [ "$(wc -c <"$work/pipe.ppm")" -eq $((13 + 16 * 16 * 3)) ] &&
  grep -q '"output": "-"' "$work/err" && ok || bad "-o - (status $status): $(head -c 100 "$work/err")"

# check: statistics on stdout, warnings (unclosed group, light inside an opaque sphere) on stderr, status 0; errors 2.
printf 'view 64 0.5\nlight 1 1 1 0 0 -3\ngroup\nmaterial 1 1 1 0 0 0 1\nmove 0 0 -3\nsphere\n' >"$work/warn.scn"
"$SNELL" check "$work/warn.scn" --json >"$work/check" 2>"$work/err"; status=$?
[ $status -eq 0 ] && python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["spheres"] == 1 and d["true_spheres"] == 1 and d["lights"] == 1 and len(d["warnings"]) == 2' "$work/check" &&
  grep -q "warn.scn:3:1: warning: 'group' is never closed" "$work/err" && grep -q "warn.scn:6:1: warning: light 1 .* inside" "$work/err" &&
  ok || bad "check (status $status): $(cat "$work/check" "$work/err")"
"$SNELL" check "$work/bad.scn" >/dev/null 2>"$work/err"; [ $? -eq 2 ] && grep -q "bad.scn:3:9: error" "$work/err" && ok || bad "check of a bad scene"

# Standard input: - reads the scene (pipes included); the image equals the
# file's; errors name <stdin>; check reads it too.
cat "$SCENES/basic.scn" | "$SNELL" render - --size 24 -q -o "$work/stdin.png" && "$SNELL" render "$SCENES/basic.scn" --size 24 -q -o "$work/file.png" &&
  "$SNELL" compare "$work/stdin.png" "$work/file.png" --max-mean 0 --max-bad 0 >/dev/null && ok || bad "render - from a pipe"
printf 'view 8 1\nsphere\nmove 1 x 2\n' | "$SNELL" render - -o "$work/x.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "^<stdin>:3:8: error: " "$work/err" && [ ! -e "$work/x.png" ] && ok || bad "error from stdin ($status): $(cat "$work/err")"
"$SNELL" check - <"$SCENES/basic.scn" >"$work/out" 2>/dev/null && grep -q "^stdin: " "$work/out" && ok || bad "check -"

# compare for scripts: 0 agree, 1 differ (thresholds can be set), 2 trouble;
# --bound-image leaves out what the reference does not certify and says how many.
"$SNELL" render "$SCENES/showcase.scn" --size 24 -q -o "$work/other.png"
"$SNELL" compare "$work/other.png" "$work/file.png" >"$work/out"; status=$?
[ $status -eq 1 ] && grep -q "^differ: " "$work/out" && ok || bad "compare of unrelated images: status $status"
"$SNELL" compare "$work/other.png" "$work/file.png" --max-mean 255 --max-bad 100 >/dev/null && ok || bad "compare --max-mean/--max-bad"
"$SNELL" compare "$work/nothing.png" "$work/file.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "snell: error: " "$work/err" && ok || bad "compare of a missing image: status $status"
"$SNELL" render "$SCENES/basic.scn" --size 32 -q -o "$work/basic.png" || bad "render basic.scn at 32²"
"$SNELL" compare "$work/basic.png" "$work/file.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "size" "$work/err" && ok || bad "compare of images of different sizes: status $status"
"$SNELL" render "$SCENES/glass.scn" --size 32 -q --cpu --tolerance 0 --depth 3 -o "$work/ref.pfm" --bound-image "$work/bound.pfm" &&
  "$SNELL" render "$SCENES/glass.scn" --size 32 -q -o "$work/test.pfm" && ok || bad "renders for --bound-image"
"$SNELL" compare "$work/test.pfm" "$work/ref.pfm" --bound-image "$work/bound.pfm" --max-uncertain 100 --json >"$work/cmp"
python3 - "$work/cmp" <<'PY' && ok || bad "compare --bound-image: $(cat "$work/cmp")"
import json, sys
m = json.load(open(sys.argv[1]))
assert m["uncertain_pixels"] > 0 and m["pixels"] + m["uncertain_pixels"] == 32 * 32, m
PY
"$SNELL" compare "$work/test.pfm" "$work/ref.pfm" --bound-image "$work/bound.pfm" --max-uncertain 0 >"$work/out"; status=$?
[ $status -eq 1 ] && grep -q "uncertain pixels" "$work/out" && grep -q "^left out [0-9]* uncertain" "$work/out" && ok ||
  bad "compare --max-uncertain 0: status $status"

# Typos on the command line get a suggestion and status 2, as typos in scenes do.
"$SNELL" rendr "$SCENES/basic.scn" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "unknown command 'rendr'; did you mean 'render'?" "$work/err" && ok || bad "snell rendr ($status): $(cat "$work/err")"
"$SNELL" render "$SCENES/basic.scn" --sise 64 -o "$work/x.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "did you mean '--size'?" "$work/err" && [ ! -e "$work/x.png" ] && ok || bad "--sise ($status): $(cat "$work/err")"
"$SNELL" compare a.png b.png --max-men 1 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "did you mean '--max-mean'?" "$work/err" && ok || bad "--max-men ($status): $(cat "$work/err")"

# check and render give the same warnings: a sphere behind the camera, no light
# and no ambient, a size that makes the render expensive.
printf 'view 16 1\nmove 0 0 5\nsphere\n' >"$work/dark.scn"
"$SNELL" check "$work/dark.scn" >/dev/null 2>"$work/check-warn"
"$SNELL" render "$work/dark.scn" -o "$work/dark.png" 2>"$work/render-warn"
grep -q "dark.scn:3:1: warning: this sphere is behind the camera" "$work/check-warn" &&
  grep -q "dark.scn: warning: every sphere is behind the camera" "$work/check-warn" &&
  grep -q "dark.scn: warning: no light and no ambient" "$work/check-warn" &&
  diff "$work/check-warn" "$work/render-warn" >/dev/null && ok || bad "check and render warnings: $(cat "$work/check-warn" "$work/render-warn")"
# The cost warning counts rays: 8192² of one sphere is cheap (8e7 rays, no
# warning from check or render), 9 samples a pixel of it are not.
printf 'view 8192 1\nlight 1 1 1 0 0 5\nmove 0 0 -3\nsphere\n' >"$work/big.scn"
"$SNELL" check "$work/big.scn" >/dev/null 2>"$work/err" && [ ! -s "$work/err" ] && ok || bad "warned of a cheap render: $(cat "$work/err")"
printf 'supersample 3\n' | cat "$work/big.scn" - >"$work/big3.scn"
"$SNELL" check "$work/big3.scn" >/dev/null 2>"$work/err" &&
  grep -q "big3.scn: warning: this render traces about [0-9.]*e+08 rays (8192x8192 pixels.*--size 341 previews" "$work/err" &&
  ok || bad "no warning of an expensive render: $(cat "$work/err")"
# A render's cost is that of the pixels it renders: --region counts. The
# warnings come before the render starts; the interrupt ends a render that
# the warning rightly calls expensive.
"$SNELL" render "$work/big3.scn" --region 0 0 1 1 -o "$work/x.png" 2>"$work/err" && [ ! -s "$work/err" ] && ok ||
  bad "warned of a one-pixel region: $(cat "$work/err")"
interrupt_after "warning: this render traces" "$work/big.scn" --supersample 4 --region 0 0 8192 4096 -o "$work/x.png"
grep -q "big.scn: warning: this render traces about [0-9.]*e+08 rays (8192x4096 pixels of the region.*--size 256 without --region" "$work/err" &&
  ok || bad "no warning of an expensive region: $(cat "$work/err")"
# Beyond some thousands of spheres the count would cost more than it saves:
# the camera rays stand in, as a lower bound.
awk 'BEGIN { print "view 16384 1"; print "supersample 2"; print "light 1 1 1 0 5 5";
  for (i = 0; i < 16400; i++) printf "group\nmove %d %d -20\nscale 0.1 0.1 0.1\nsphere\ngroupend\n", i % 128 - 64, int(i / 128) - 64 }' >"$work/many.scn"
"$SNELL" check "$work/many.scn" >/dev/null 2>"$work/err" &&
  grep -q "many.scn: warning: this render traces at least 1.1e+09 rays (16384x16384 pixels, 4 camera rays each)" "$work/err" &&
  ok || bad "no lower bound for a scene of many spheres: $(cat "$work/err")"
"$SNELL" render "$work/big.scn" --size 64 -o "$work/big.png" 2>"$work/err" && [ ! -s "$work/err" ] && ok || bad "warned at a small size: $(cat "$work/err")"
"$SNELL" render "$SCENES/basic.scn" --size 24 -o "$work/x.png" 2>"$work/err" && [ ! -s "$work/err" ] && ok || bad "warnings on a plain scene: $(cat "$work/err")"
# Amplifying materials at the defaults, on a large image: the cost and the
# cheaper fixed tree are named; asking for a tree silences it.
sed 's/^view 256 /view 4096 /' "$SCENES/glass.scn" >"$work/glass4k.scn"
"$SNELL" check "$work/glass4k.scn" >/dev/null 2>"$work/err" &&
  grep -q "glass4k.scn: warning: at the defaults this render may trace up to .* --depth 5 --min-weight 0" "$work/err" && ok ||
  bad "no warning of an expensive amplifying render: $(cat "$work/err")"
# (The scene's own warnings come first; the defaults' would follow them.)
interrupt_after "glass4k.scn:23:3: warning" "$work/glass4k.scn" --depth 5 -o "$work/x.png"
grep -q "glass4k.scn:23:3: warning" "$work/err" && ! grep -q "at the defaults" "$work/err" && ok ||
  bad "the defaults' warning with a fixed tree: $(cat "$work/err")"

# Light that may grow (a trap) dropped for want of frontier room: the GPU says
# which pixels, and claims no estimate for them; the reference keeps it all.
"$SNELL" render "$SCENES/hard/glass-in-water-gap-0.scn" --size 48 --stats -o "$work/x.png" >"$work/stats" 2>"$work/err"
grep -q "warning: [0-9]* pixel(s) dropped light trapped in a material with ks + kt > 1.*e.g. ([0-9]*, [0-9]*)" "$work/err" &&
  python3 -c '
import json, sys
t = json.load(open(sys.argv[1]))["truncation"]
assert t["dropped_growing_pixels"] > 0 and t["over_tolerance_pixels"] >= t["dropped_growing_pixels"], t
assert t["estimated_pixels"] + t["dropped_growing_pixels"] <= t["unbounded_pixels"], t' "$work/stats" && ok ||
  bad "no report of dropped light that may grow: $(cat "$work/err" "$work/stats")"
"$SNELL" render "$SCENES/hard/glass-in-water-gap-0.scn" --size 48 --cpu --stats -o "$work/x.png" >"$work/stats" 2>"$work/err"
! grep -q "dropped light trapped" "$work/err" && grep -q '"dropped_growing_pixels": 0' "$work/stats" && ok ||
  bad "the reference reported dropped light: $(cat "$work/err")"

# --count-lanes measures the kernel without changing the image: shares of busy
# lanes in [0, 1], a BVH walk counted only where there is a BVH.
"$SNELL" render "$SCENES/grid.scn" --size 32 -q -o "$work/lanes.png" --count-lanes --stats >"$work/stats" &&
  "$SNELL" render "$SCENES/grid.scn" --size 32 -q -o "$work/nolanes.png" &&
  "$SNELL" compare "$work/lanes.png" "$work/nolanes.png" --max-mean 0 --max-bad 0 >/dev/null &&
  python3 - "$work/stats" <<'PY' && ok || bad "--count-lanes: $(tail -n 1 "$work/stats")"
import json, sys
lanes = json.loads(open(sys.argv[1]).read().splitlines()[-1])["lanes"]
assert 0 < lanes["trace_busy"] <= lanes["trace_slots"] and 0 < lanes["trace_occupancy"] <= 1, lanes
assert 0 < lanes["walk_busy"] <= lanes["walk_slots"] and 0 < lanes["walk_occupancy"] <= 1, lanes
PY

# --traversal: --stats names the search that ran; ray queries, where the
# device has them, trace the very image of snell's walk, and where it has
# none (Mesa 22.3's lavapipe) they are refused with the reason, status 1.
"$SNELL" render "$SCENES/grid.scn" --size 32 -q -o "$work/walk.pfm" --traversal bvh --stats >"$work/stats" &&
  grep -q '"traversal": "bvh"' "$work/stats" && ok || bad "--traversal bvh: $(tail -n 1 "$work/stats")"
"$SNELL" render "$SCENES/basic.scn" --size 32 -q -o "$work/loop.pfm" --stats >"$work/stats" &&
  grep -q '"traversal": "loop"' "$work/stats" && ok || bad "one sphere is not a loop: $(tail -n 1 "$work/stats")"
"$SNELL" render "$SCENES/grid.scn" --size 32 -q -o "$work/query.pfm" --traversal ray-query --stats >"$work/stats" 2>"$work/err"
status=$?
if "$SNELL" devices | grep -q "no ray queries"; then
  [ $status -eq 1 ] && grep -q "ray-query: the device lacks VK_KHR_" "$work/err" && ok ||
    bad "--traversal ray-query without ray queries: status $status, $(cat "$work/err")"
else
  [ $status -eq 0 ] && grep -q '"traversal": "ray-query"' "$work/stats" && cmp -s "$work/walk.pfm" "$work/query.pfm" && ok ||
    bad "--traversal ray-query: status $status, $(cat "$work/err") $(tail -n 1 "$work/stats")"
fi
"$SNELL" render "$SCENES/grid.scn" --size 8 --traversal ray-query --precision fp64 -o "$work/x.png" 2>"$work/err"
[ $? -eq 1 ] && grep -q "fp32" "$work/err" && ok || bad "--traversal ray-query with fp64: $(cat "$work/err")"
"$SNELL" render "$SCENES/grid.scn" --size 8 --traversal rtx -o "$work/x.png" 2>/dev/null
[ $? -eq 2 ] && ok || bad "--traversal rtx accepted"

echo "cli (rendering): $pass passed, $fail failed"
[ $fail -eq 0 ]
