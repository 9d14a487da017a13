#!/usr/bin/env bash
# What the command line says, and when: every mistake on it in snell's one
# voice (snell: error: ..., a pointer to --help, status 2, ranges in words);
# GPU options refused with --cpu, and --stats stating the settings used;
# every output path checked before the render; -o - refusing a terminal;
# the kernel's compile announced on the bar's line and left out of its
# rate; -v in words that add up. A terminal is script(1)'s pseudo-terminal.
#   SNELL=$PWD/build/snell SCENES=$PWD/scenes bash tests/cli_voice_test.sh
# shellcheck source=tests/cli_test_support.sh
source "$(dirname "$0")/cli_test_support.sh"
scene=$SCENES/basic.scn
have_script=0
command -v script >/dev/null && have_script=1 || echo "note: script(1) is not installed: the terminal cases are skipped"
# Runs a command line on a pseudo-terminal; its transcript (stdout and stderr) in $work/tty, its status returned.
on_terminal() { script -qec "$1" "$work/tty" >/dev/null 2>&1; }

# 1. The option library's mistakes, in every subcommand: one line, snell's
# voice, the subcommand's help named, status 2, nothing of CLI11's phrasing,
# no bound of 300 digits.
mistakes=(
  "render" "render $scene $scene" "render $scene -s abc" "render $scene -s 0" "render $scene --spp 1.5"
  "render $scene --min-weight 2" "render $scene --min-weight -1" "render $scene --tolerance nan"
  "render $scene --depth x" "render $scene --region 1 2" "render $scene --region 1 2 3 4 5"
  "render $scene --region a 0 4 4" "render $scene -o a.png -o b.png" "render $scene --precision fp16"
  "render $scene --traversal walk" "render $scene --exr-compression lzw" "render $scene --tree-budget -1"
  "render $scene --gpu -1" "render $scene --cpu=abc" "render $scene --frobnicate" "render --frobnicate"
  "render -q=3 $scene" "render $scene -o x.jpg"
  "compare a.png" "compare a.png b.png --max-mean -1" "compare a.png b.png --max-bad 101"
  "compare a.png b.png --bad-threshold 256" "compare a.png b.png --bound-image $work/none.pfm"
  "compare a.png b.png --max-uncertain x"
  "assemble a.exr" "assemble -o x.png" "assemble -o x.png -s 0 a.exr"
  "bench --runs 2" "bench -s 7" "bench --gpu x"
  "check" "check $scene $scene" "devices extra"
  "preview" "preview $scene --screenshot a.png" "preview $scene -s 0" "preview $scene --frames 0"
  "preview $scene --orbit nan"
  "--bogus" "rendr $scene" "frob"
)
for args in "${mistakes[@]}"; do
  # shellcheck disable=SC2086
  (cd "$work" && "$SNELL" $args) >"$work/out" 2>"$work/err"; status=$?
  first=$(head -n 1 "$work/err")
  cli11='[0-9]{20}|Run with --help|required but|not in range|Could not convert|is required|not expected'
  if [ $status -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && [[ $first == "snell: error: "* ]] &&
    [[ $first == *"--help"* ]] && ! grep -qE "$cli11" "$work/err"; then
    ok
  else
    bad "snell $args: status $status: $(cat "$work/err")"
  fi
done
"$SNELL" compare a.png b.png --max-mean -1 2>"$work/err"
grep -q -- "--max-mean: must be a number, 0 or more, not '-1'" "$work/err" && ok ||
  bad "--max-mean -1: $(cat "$work/err")"
"$SNELL" render "$scene" -s abc 2>"$work/err"
grep -q -- "--size: must be a whole number from 1 to 16384, not 'abc'" "$work/err" && ok ||
  bad "-s abc: $(cat "$work/err")"
# The environment's device settings are named as such.
SNELL_GPU=x "$SNELL" render "$scene" -s 8 -o "$work/env.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "^snell: error: SNELL_GPU: must be a whole number" "$work/err" &&
  [ ! -e "$work/env.png" ] && ok || bad "SNELL_GPU=x: status $status: $(cat "$work/err")"

# 2. GPU options with --cpu: refused, each one, before anything is written;
# their environment variables are preferences, not refused.
for option in "--precision fp64" "--precision fp32" "--gpu 0" "--traversal bvh" "--validation" "--count-lanes"; do
  # shellcheck disable=SC2086
  "$SNELL" render "$scene" --cpu -s 8 $option -o "$work/cpu.png" 2>"$work/err"; status=$?
  [ $status -eq 2 ] && grep -q "^snell: error: ${option%% *} applies to GPU renders only" "$work/err" &&
    [ ! -e "$work/cpu.png" ] && ok || bad "--cpu $option: status $status: $(cat "$work/err")"
done
"$SNELL" render "$scene" --cpu -s 8 --precision fp64 --gpu 0 --traversal bvh -o "$work/cpu.png" 2>"$work/err"
grep -q -- "--gpu, --precision and --traversal apply to GPU renders only" "$work/err" && ok ||
  bad "--cpu with three GPU options: $(cat "$work/err")"
"$SNELL" render --help | grep -q -- "are refused with it" && ok ||
  bad "render --help does not say --cpu refuses GPU options"
# The settings --stats reports are the ones used: 1e-7 and 0.01/255, not 0.000000.
SNELL_GPU=5 SNELL_TRAVERSAL=bvh SNELL_VALIDATION=1 \
  "$SNELL" render "$scene" --cpu -s 8 -q --stats -o "$work/cpu.png" >"$work/stats" 2>"$work/err"; status=$?
[ $status -eq 0 ] && ok || bad "--cpu with the GPU's environment variables set: status $status: $(cat "$work/err")"
python3 - "$work/stats" <<'EOF' && ok || bad "--cpu --stats: $(tail -n 1 "$work/stats")"
import json, sys
stats = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
assert stats["min_weight"] == 1e-7, stats["min_weight"]
assert stats["tolerance"] == 0.01 / 255, stats["tolerance"]
EOF

# 3. Every output is checked before the render: nothing is rendered or
# written when the bound image cannot be, an existing output kept.
echo "precious" >"$work/kept.png"
"$SNELL" render "$scene" -s 16 -q --bound-image "$work/nodir/b.pfm" -o "$work/kept.png" 2>"$work/err"; status=$?
[ $status -eq 1 ] && grep -q "^snell: error: cannot write '$work/nodir/b.pfm': directory '$work/nodir' does not exist" \
  "$work/err" && [ "$(cat "$work/kept.png")" = "precious" ] && ok ||
  bad "--bound-image in a missing directory: status $status," \
    "output '$(head -c 20 "$work/kept.png" | tr -cd '[:print:]')': $(cat "$work/err")"
"$SNELL" render "$scene" -s 16 -q --bound-image "$work/nodir/b.pfm" -o "$work/new.png" 2>/dev/null
[ ! -e "$work/new.png" ] && ok || bad "a render whose --bound-image cannot be written wrote its image first"
"$SNELL" preview "$scene" --frames 1 --screenshot "$work/nodir/s.png" 2>"$work/err"; status=$?
[ $status -eq 1 ] && grep -q "does not exist" "$work/err" && ok ||
  bad "preview --screenshot in a missing directory: status $status: $(cat "$work/err")"

# 4. -o - refuses a terminal (nothing rendered), and pipes PPM elsewhere.
if [ $have_script -eq 1 ]; then
  on_terminal "$SNELL render $scene -s 16 -o -"; status=$?
  [ $status -eq 2 ] && grep -aq "snell: error: .*standard output, which is a terminal" "$work/tty" &&
    ! grep -aq "P6" "$work/tty" && ok || bad "-o - on a terminal: status $status: $(head -c 300 "$work/tty")"
fi
[ "$("$SNELL" render "$scene" -s 16 -q -o - | head -c 2)" = "P6" ] && ok || bad "-o - into a pipe is not PPM"

# 5. -v in words: counts in the singular where one, what the probe is for,
# and a wait for the encoder no longer than the encoding.
check_verbose() {
  grep -aqE "\b1 (tiles|dispatches)\b" "$1" && bad "-v says '1 tiles' or '1 dispatches': $(grep -a render "$1")" || ok
  grep -aqE "render [0-9.]+ ms \(timed by the (GPU|host)" "$1" && ok || bad "-v has no render time: $(cat "$1")"
  awk '/write [0-9.]+ ms/ {
         w = $0; sub(/.*write /, "", w); split(w, t, " "); total = t[1]
         if (w ~ /on the render.s thread/) ok = 1
         else if (match(w, /waited [0-9.]+ ms/)) { split(substr(w, RSTART + 7), u, " "); ok = (u[1] <= total) }
       }
       END { exit !ok }' "$1" && ok || bad "-v's write time does not add up: $(grep -a write "$1")"
}
"$SNELL" render "$scene" -s 16 -v -o "$work/v.png" 2>"$work/err" && check_verbose "$work/err"
"$SNELL" render "$scene" -s 16 -v --cpu -o "$work/v.exr" 2>"$work/err" && check_verbose "$work/err"
if [ $have_script -eq 1 ]; then
  on_terminal "$SNELL render $scene -s 256 -v -o $work/probe.png"
  probe="time-left probe [0-9.]* ms (1 pixel in 256, rendered first for the progress bar's time left)"
  grep -aq "$probe" "$work/tty" && ok || bad "-v does not say what its probe estimates: $(grep -a probe "$work/tty")"

  # 6. A kernel compiled for a new scene structure (caches of its own, both
  # empty) is announced on the bar's line, and the bar's rays a second are
  # the render's: with the compile in its clock the rate could not exceed
  # the rays over the compile's time. On a device that compiles in under a
  # second there is nothing to announce and no such bound.
  SNELL_CACHE_DIR="$work/cold" MESA_SHADER_CACHE_DIR="$work/cold-mesa" \
    on_terminal "$SNELL render $SCENES/glass.scn -s 32 --stats -o $work/cold.png"
  tr '\r' '\n' <"$work/tty" >"$work/lines"
  python3 - "$work/lines" <<'EOF' && ok || bad "the compile: $(grep -a -e compiling -e Mrays "$work/lines" | tail -n 2)"
import json, re, sys
text = open(sys.argv[1], errors="replace").read()
stats = json.loads(next(l for l in text.splitlines() if l.startswith("{")))
if stats["pipeline_ms"] < 1000:
    print(f"note: the kernel compiled in {stats['pipeline_ms']:.0f} ms: nothing to announce")
    sys.exit(0)
assert "snell: compiling the kernel for this scene..." in text, "no announcement"
rates = [float(r) for r in re.findall(r"([0-9.e+-]+) Mrays/s", text)]
assert rates, "no rate on the bar"
with_compile = stats["rays"]["total"] / stats["pipeline_ms"] * 1e-3  # Mrays/s
assert rates[-1] > 10 * with_compile, f"the bar's {rates[-1]} Mrays/s counts the compile ({with_compile:.3g})"
EOF
fi

echo "cli voice: $pass passed, $fail failed"
[ $fail -eq 0 ]
