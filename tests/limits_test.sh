#!/usr/bin/env bash
# The documented limits render on this Vulkan driver and agree with the CPU
# reference: a scene of 65 536 lights (where the driver limits loops, one
# ray's shading spans dispatches) and one of 4 000 000 spheres (the scene's
# buffers within the device's limits). Status and image checked, not time.
# LIMITS_SCENES="lights" or "spheres" renders one of them (side by side
# under ctest); by default both. Under ctest the scene and its CPU reference
# are made once (LIMITS_STEP=prepare, into LIMITS_DIR) for the GPU renders on
# each driver (LIMITS_STEP=gpu); by default all of it, in a temporary folder.
set -u
: "${SNELL:?}" "${SOURCE:?}" "${PYTHON:=python3}"
scenes=${LIMITS_SCENES:-lights spheres}
step=${LIMITS_STEP:-all}
if [ -n "${LIMITS_DIR:-}" ]; then
  work=$LIMITS_DIR
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }

# Two spheres (one a mirror) and 65 536 lights spread above them.
if [ "$step" != gpu ] && [[ " $scenes " == *" lights "* ]]; then
  "$PYTHON" - "$work/lights.scn" <<'PY'
import random, sys
rng = random.Random(65536)
with open(sys.argv[1], "w") as f:
    f.write("view 32 0.5\nambient 0.05 0.05 0.05\n")
    f.write("group\nmove -0.6 0 -3\nsphere\ngroupend\n")
    f.write("group\nmaterial 0.5 0.5 0.5 0.5 0.5 0.5 10\nmove 1.2 0 -3\nscale 0.8 0.8 0.8\nsphere\ngroupend\n")
    for _ in range(65536):
        c = 4.0 / 65536
        f.write(f"light {c:.8f} {c:.8f} {c:.8f} {rng.uniform(-10, 10):.3f} {rng.uniform(-10, 10):.3f} "
                f"{rng.uniform(2, 10):.3f}\n")
PY
fi

# 3 999 999 spheres in a jittered grid, and a floor: 4 000 000.
if [ "$step" != gpu ] && [[ " $scenes " == *" spheres "* ]]; then
  "$PYTHON" "$SOURCE/bench/make_scaling_scene.py" 3999999 >"$work/spheres.scn"
  grep -c '^sphere' "$work/spheres.scn" | grep -qx 4000000 && ok || bad "the sphere scene does not hold 4 000 000 spheres"
fi

# Agreement with the CPU reference, every pixel counted: at 32² nearly every
# pixel of the sphere scene is the silhouette of spheres about a pixel
# across, whose hit or miss float and double may decide differently (0.12-0.2 %
# of pixels before the GPU traced such pixels again in double), hence 0.5 %.
for scene in $scenes; do
  if [ "$step" != gpu ]; then
    "$SNELL" render "$work/$scene.scn" --size 32 --cpu -q -o "$work/$scene-cpu.pfm" 2>"$work/err" && ok ||
      bad "$scene: the CPU render failed: $(cat "$work/err")"
  fi
  [ "$step" = prepare ] && continue
  "$SNELL" render "$work/$scene.scn" --size 32 -q -o "$work/$scene-gpu-$$.pfm" 2>"$work/err" && ok ||
    bad "$scene: the GPU render failed: $(cat "$work/err")"
  "$SNELL" compare --json --max-bad 0.5 "$work/$scene-gpu-$$.pfm" "$work/$scene-cpu.pfm" >"$work/cmp" &&
    "$PYTHON" -c 'import json,sys; d=json.load(sys.stdin); sys.exit(0 if d["mean_abs_error"] <= 0.5 and d["bad_fraction"] <= 0.005 and d["non_finite"] == 0 else 1)' <"$work/cmp" &&
    ok || bad "$scene: GPU and CPU differ: $(cat "$work/cmp")"
  rm -f "$work/$scene-gpu-$$.pfm"
done

echo "limits ($step): $pass passed, $fail failed"
[ $fail -eq 0 ]
