#!/usr/bin/env bash
# The preview window through a real X server (Xvfb), window and
# swapchain, with the Khronos validation layer on: the scripted screenshot of
# a scene with reflection and refraction equals `snell render` of it (within
# the GPU-vs-CPU thresholds), an orbit changes it, saving the scene file
# re-renders it, a broken save is reported as FILE:LINE:COL and survived, a
# moving camera renders small frames, and no display is a clear error.
set -u
: "${SNELL:?}" "${SCENES:?}"
work=$(mktemp -d)
xvfb_pid=""
cleanup() { [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null; rm -rf "$work"; }
trap cleanup EXIT
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }

command -v Xvfb >/dev/null || { echo "FAIL: Xvfb is not installed (apt-get install xvfb)"; exit 1; }
Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp 3>"$work/display" 2>"$work/xvfb.log" &
xvfb_pid=$!
for _ in $(seq 50); do [ -s "$work/display" ] && break; sleep 0.1; done
[ -s "$work/display" ] || { echo "FAIL: Xvfb did not start: $(cat "$work/xvfb.log")"; exit 1; }
export DISPLAY=":$(head -n 1 "$work/display")"
export SNELL_VALIDATION=1

within_thresholds() {  # compare JSON on stdin: mean <= 0.5/255, bad <= 0.1 %
  python3 -c 'import json,sys; d=json.load(sys.stdin); sys.exit(0 if d["mean_abs_error"] <= 0.5 and d["bad_fraction"] <= 0.001 and d["non_finite"] == 0 else 1)'
}

# Scripted preview of the showcase (glass, mirrors, 2x2 supersampling: four
# progressive frames, then two more) against the headless render.
scene="$SCENES/showcase.scn"
"$SNELL" preview "$scene" --size 128 --frames 6 --screenshot "$work/shot.png" 2>"$work/err"; status=$?
[ $status -eq 0 ] && [ -s "$work/shot.png" ] && ok || bad "scripted preview (status $status): $(cat "$work/err")"
grep -q "validation" "$work/err" && bad "validation layer messages: $(cat "$work/err")" || ok
"$SNELL" render "$scene" --size 128 -q -o "$work/render.png" && ok || bad "render"
"$SNELL" compare --json "$work/shot.png" "$work/render.png" >"$work/cmp" && within_thresholds <"$work/cmp" && ok ||
  bad "screenshot differs from the render: $(cat "$work/cmp")"

# An orbit changes the image.
"$SNELL" preview "$scene" --size 128 --frames 4 --orbit 40 --screenshot "$work/orbit.png" 2>"$work/err"; status=$?
[ $status -eq 0 ] && ok || bad "orbit preview (status $status): $(cat "$work/err")"
"$SNELL" compare --json "$work/orbit.png" "$work/render.png" >"$work/cmp"; [ $? -eq 1 ] &&
  python3 -c 'import json,sys; d=json.load(sys.stdin); sys.exit(0 if d["mean_abs_error"] > 1 else 1)' <"$work/cmp" && ok ||
  bad "the orbit did not change the image: $(cat "$work/cmp")"

# The moving camera: every frame orbits, as a drag would, and is rendered small
# enough to keep up (the frame rate is reported, never asserted here).
"$SNELL" preview "$scene" --size 256 --frames 8 --orbit-per-frame 3 2>"$work/err"; status=$?
[ $status -eq 0 ] && grep -q "rendered (moving, [0-9]*x[0-9]* of 256x256).*frames a second" "$work/err" && ok ||
  bad "moving preview (status $status): $(cat "$work/err")"

# Hot reload: a running preview re-renders a saved change, reports a broken
# save as FILE:LINE:COL and keeps going; Ctrl-C closes it (status 130).
cp "$SCENES/basic.scn" "$work/live.scn"
"$SNELL" preview "$work/live.scn" --size 64 2>"$work/live.err" &
pid=$!
sleep 2
sed -i 's/^material 0.8 0.3 0.2/material 0.2 0.3 0.8/' "$work/live.scn"
for _ in $(seq 50); do grep -q "reloaded" "$work/live.err" && break; sleep 0.1; done
grep -q "reloaded .*live.scn: new image" "$work/live.err" && ok || bad "no hot reload: $(cat "$work/live.err")"
printf 'view 64 0.5\nsphere 1\n' >"$work/live.scn"
for _ in $(seq 50); do grep -q "error:" "$work/live.err" && break; sleep 0.1; done
grep -q "live.scn:2:8: error: " "$work/live.err" && ok || bad "broken save not reported: $(cat "$work/live.err")"
kill -0 $pid 2>/dev/null && ok || bad "the preview died on a broken save"
kill -INT $pid
wait $pid; status=$?
[ $status -eq 130 ] && ok || bad "Ctrl-C status $status (want 130)"
grep -q "validation" "$work/live.err" && bad "validation layer messages: $(cat "$work/live.err")" || ok

# No display: a clear error, status 1.
env -u DISPLAY -u WAYLAND_DISPLAY "$SNELL" preview "$scene" --frames 1 2>"$work/err"; status=$?
[ $status -eq 1 ] && grep -q "cannot open a window" "$work/err" && ok || bad "no display (status $status): $(cat "$work/err")"

# The keys are in --help.
"$SNELL" preview --help | grep -q "restore the scene's camera" && ok || bad "preview --help lists no keys"

echo "preview: $pass passed, $fail failed"
[ $fail -eq 0 ]
