#!/usr/bin/env bash
# The command line as a user meets it: exit statuses, the FILE:LINE:COL error
# format, --help/--version, the kept caches, --stats JSON, every output format,
# and that a failed render never writes, truncates or clobbers an output file.
# Rendering's own cases are in tests/cli_render_test.sh.
# shellcheck source=tests/cli_test_support.sh
source "$(dirname "$0")/cli_test_support.sh"

# --help and --version
"$SNELL" --help >"$work/help" 2>&1 && grep -q "render" "$work/help" && grep -q "Exit status" "$work/help" && ok || bad "--help"
"$SNELL" render --help >"$work/rhelp" 2>&1 && grep -q -- "--stats" "$work/rhelp" && ok || bad "render --help"
"$SNELL" --version >"$work/version" 2>&1 && grep -q "^snell [0-9]" "$work/version" && ok || bad "--version"

# A scene error: status 2, FILE:LINE:COL message, existing output untouched.
printf 'view 16 0.5\nsphere\nscale 1 0 1\n' >"$work/bad.scn"
echo "precious" >"$work/out.png"
"$SNELL" render "$work/bad.scn" -o "$work/out.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && ok || bad "scene error exit status $status (want 2)"
grep -q "^$work/bad.scn:3:9: error: " "$work/err" && ok || bad "error format: $(cat "$work/err")"
[ "$(cat "$work/out.png")" = "precious" ] && ok || bad "output clobbered by a failed render"
[ -z "$(ls "$work" | grep tmp)" ] && ok || bad "temporary file left behind"

# Missing file and directory as input: status 2, the file named without a position.
"$SNELL" render "$work/nope.scn" -o "$work/x.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "nope.scn: error: cannot open scene file: No such file or directory" "$work/err" && [ ! -e "$work/x.png" ] && ok || bad "missing file ($status)"
"$SNELL" render "$work" -o "$work/x.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "directory" "$work/err" && ok || bad "directory as input ($status)"

# Bad command line, an unknown output format included: status 2 with a message,
# nothing rendered. An unwritable directory: status 1 before rendering.
for args in "--size 0" "--min-weight nan" "--min-weight inf" "--min-weight -1" "--depth x" "--precision fp16"; do
  # shellcheck disable=SC2086
  "$SNELL" render "$SCENES/basic.scn" $args -o "$work/x.png" 2>"$work/err"; status=$?
  [ $status -eq 2 ] && [ -s "$work/err" ] && [ ! -e "$work/x.png" ] && ok || bad "render $args: status $status"
done
"$SNELL" preview "$SCENES/basic.scn" --orbit nan 2>/dev/null; [ $? -eq 2 ] && ok || bad "preview --orbit nan"
"$SNELL" render "$SCENES/basic.scn" -o "$work/x.jpg" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q ".png, .ppm, .pfm or .exr" "$work/err" && ok || bad "unknown extension ($status)"
"$SNELL" render "$SCENES/basic.scn" -o "$work/no/such/dir/x.png" 2>"$work/err"; status=$?
[ $status -eq 1 ] && grep -q "does not exist" "$work/err" && ok || bad "missing output dir ($status)"

# Where a cache directory is kept, the kernel's specialisation is folded in
# before the driver sees it (kept there for the next run), with the same
# image; without one, the driver specialises it.
"$SNELL" render "$SCENES/glass.scn" --size 24 -q -o "$work/folded.pfm" --stats 2>/dev/null | tail -n 1 >"$work/stats"
grep -q '"kernel": "folded"' "$work/stats" && ls "$SNELL_CACHE_DIR"/modules/*.spv >/dev/null 2>&1 && ok ||
  bad "no folded kernel with a cache: $(cat "$work/stats")"
MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$HOME/.cache/mesa_shader_cache}" SNELL_CACHE_DIR= XDG_CACHE_HOME= HOME= \
  "$SNELL" render "$SCENES/glass.scn" --size 24 -q -o "$work/driver.pfm" --stats 2>/dev/null |
  tail -n 1 >"$work/stats"
grep -q '"kernel": "driver"' "$work/stats" && cmp -s "$work/driver.pfm" "$work/folded.pfm" && ok ||
  bad "without a cache: $(cat "$work/stats")"

# Where the device has shader objects and validation is off, the kernel is one
# whose driver binary is kept: the next run starts from that binary, with the
# same image; elsewhere it is a pipeline.
rm -rf "$SNELL_CACHE_DIR/shaders"
for run in first second; do
  SNELL_VALIDATION=0 "$SNELL" render "$SCENES/glass.scn" --size 24 -q -o "$work/$run.pfm" --stats 2>/dev/null |
    tail -n 1 >"$work/stats-$run"
done
if "$SNELL" devices | grep -q "kernels: kept driver binaries"; then
  grep -q '"kernel_object": "shader object"' "$work/stats-first" && ok || bad "first run: $(cat "$work/stats-first")"
  grep -q '"kernel_object": "shader binary"' "$work/stats-second" && ls "$SNELL_CACHE_DIR"/shaders/*.bin >/dev/null 2>&1 &&
    ok || bad "second run: $(cat "$work/stats-second")"
else
  grep -q '"kernel_object": "pipeline"' "$work/stats-second" && ok || bad "no shader objects: $(cat "$work/stats-second")"
fi
cmp -s "$work/first.pfm" "$work/folded.pfm" && cmp -s "$work/second.pfm" "$work/folded.pfm" && ok ||
  bad "the kernel's binary traced another image"
# What the driver's loop-limit probe found is kept too (lavapipe only), and a
# damaged answer is probed again.
if "$SNELL" --version | grep -q llvmpipe; then
  probe=$(ls "$SNELL_CACHE_DIR"/probes/*.probe 2>/dev/null | head -n 1)
  [ -n "$probe" ] && ok || bad "no kept probe in $SNELL_CACHE_DIR/probes"
  if [ -n "$probe" ]; then
    printf 'x' >>"$probe"
    "$SNELL" render "$SCENES/basic.scn" --size 8 -q -o "$work/probed.png" || bad "render after a damaged probe"
    case "$(tail -c 1 "$probe")" in 0 | 1) ok ;; *) bad "damaged probe not made again" ;; esac
  fi
fi
SNELL_VALIDATION=1 "$SNELL" render "$SCENES/glass.scn" --size 24 -q -o "$work/validated.pfm" --stats 2>/dev/null |
  tail -n 1 | grep -q '"kernel_object": "pipeline"' && ok || bad "shader objects under validation"

# No Vulkan driver at all: status 1, a message naming the package, no file.
VK_ICD_FILENAMES=/nonexistent/icd.json "$SNELL" render "$SCENES/basic.scn" -o "$work/nodev.png" 2>"$work/err"; status=$?
[ $status -eq 1 ] && grep -q "mesa-vulkan-drivers" "$work/err" && [ ! -e "$work/nodev.png" ] && ok || bad "no Vulkan driver ($status): $(cat "$work/err")"

# A good render in every format, with --stats as the last line of stdout.
for ext in png ppm pfm; do
  "$SNELL" render "$SCENES/basic.scn" --size 32 -o "$work/basic.$ext" --stats >"$work/stats" 2>"$work/err"; status=$?
  [ $status -eq 0 ] && [ -s "$work/basic.$ext" ] && ok || bad "render .$ext ($status): $(cat "$work/err")"
done
tail -n 1 "$work/stats" | python3 -c '
import json, sys
d = json.loads(sys.stdin.read())
for k in ("parse_ms", "upload_ms", "render_ms", "readback_ms", "write_ms", "total_ms", "device"):
    assert k in d, k
for k in ("primary", "shadow", "reflected", "refracted"):
    assert k in d["rays"], k
assert d["rays"]["primary"] == 32 * 32, d["rays"]
assert d["width"] == 32
' && ok || bad "--stats JSON"
head -c 2 "$work/basic.ppm" | grep -q P6 && ok || bad "PPM magic"
head -c 2 "$work/basic.pfm" | grep -q PF && ok || bad "PFM magic"

# The CPU back end renders the same scene, and compare agrees with itself.
"$SNELL" render "$SCENES/basic.scn" --size 32 --cpu -o "$work/cpu.png" 2>/dev/null && ok || bad "--cpu"
"$SNELL" compare --json "$work/basic.png" "$work/cpu.png" >"$work/cmp" && grep -q mean_abs_error "$work/cmp" && ok || bad "compare --json"
"$SNELL" compare "$work/basic.png" "$work/basic.png" --diff "$work/diff.png" >"$work/cmp" &&
  grep -q "mean abs error 0.0000/255" "$work/cmp" && [ -s "$work/diff.png" ] && ok || bad "compare (text, --diff): $(cat "$work/cmp")"
# EXR: written, read back by compare, equal to the PFM of the same render.
"$SNELL" render "$SCENES/basic.scn" --size 32 -o "$work/basic.exr" -q && "$SNELL" compare --json "$work/basic.exr" "$work/basic.pfm" |
  grep -q '"max_error": 0' && ok || bad "EXR output"
# Every EXR compression is lossless, and a compression snell does not know is a usage error.
for c in piz rle zip none; do
  "$SNELL" render "$SCENES/showcase.scn" --size 48 -q --exr-compression $c -o "$work/c-$c.exr" &&
    "$SNELL" render "$SCENES/showcase.scn" --size 48 -q -o "$work/c-ref.pfm" &&
    "$SNELL" compare --json "$work/c-$c.exr" "$work/c-ref.pfm" | grep -q '"max_error": 0' && ok ||
    bad "EXR with --exr-compression $c is not the PFM's image"
done
"$SNELL" render "$SCENES/basic.scn" --size 8 --exr-compression lzma -o "$work/c.exr" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "piz" "$work/err" && [ ! -e "$work/c.exr" ] && ok || bad "unknown EXR compression ($status)"

echo "cli: $pass passed, $fail failed"
[ $fail -eq 0 ]
