#!/usr/bin/env bash
# Memory over a long render: `snell render` runs for SOAK_SECONDS on a scene
# whose ray trees never end (an amplifying glass sphere, no cut-off, no tree
# budget), so the renderer dispatches for the whole time; its resident size
# is sampled every 2 s and must not grow by more than SOAK_GROWTH_MB after the
# first band (SOAK_SETTLE seconds), in which the image, the pipeline and the
# invocations' stacks are allocated once. On Debian 12's Mesa 22.3 lavapipe,
# which dispatches several times a second here, two kernels grew by 0.5-0.75
# MB a dispatch, the driver compiling and keeping a new copy of the shader at
# every dispatch: an early one that wrote pixels through a storage image, and
# one it specialised on a uniform value (docs/design.md, No recompiles per
# dispatch); either would grow by hundreds of MB here. The render is then
# ended with SIGTERM and must exit 143, leaving no file. Given SECOND_ICD, a
# second render on that driver runs beside the first.
set -u
: "${SNELL:?}"
seconds=${SOAK_SECONDS:-120}
settle=${SOAK_SETTLE:-20}
growth=${SOAK_GROWTH_MB:-8}
work=$(mktemp -d)
trap 'pkill -9 -f "$work/trapped.scn" 2>/dev/null; rm -rf "$work"' EXIT
cat >"$work/trapped.scn" <<'SCENE'
view 64 0.5
background 0.1 0.2 0.6
light 1 1 1 3 4 3
material 0.1 0.1 0.1 0.5 0.5 0.5 50
refraction 1 1 1 25
move 0 0 -3
sphere
material 0.3 0.3 0.3 1 1 1 5
move 0.6 0.6 -3
scale 0.7 0.7 0.7
sphere
SCENE
# soak NAME [ENV...]: one render on the driver ENV names, sampled and ended;
# prints its findings, exits non-zero on a failure.
soak() {
  local name=$1 dir="$work/$1" pid status samples=() t rss base peak fail=0
  shift
  mkdir -p "$dir"
  env "$@" "$SNELL" render "$work/trapped.scn" -q --size 48 --tolerance 0 --min-weight 0 --depth 200 \
    --tree-budget 1000000000 -o "$dir/out.png" 2>"$dir/err" &
  pid=$!
  for ((t = 0; t < seconds; t += 2)); do
    sleep 2
    rss=$(ps -o rss= -p $pid 2>/dev/null) || { echo "FAIL ($name): the render ended early: $(cat "$dir/err")"; return 1; }
    samples+=("$t $((rss / 1024))")
  done
  kill -TERM $pid
  wait $pid; status=$?
  printf '%s\n' "${samples[@]}" >"$dir/rss"
  echo "$name: resident MB over time (s MB): $(tr '\n' ';' <"$dir/rss")"
  base=$(awk -v s="$settle" '$1 >= s { print $2; exit }' "$dir/rss")
  peak=$(awk -v s="$settle" '$1 >= s && $2 > m { m = $2 } END { print m }' "$dir/rss")
  [ "$status" -eq 143 ] || { echo "FAIL ($name): SIGTERM gave status $status (want 143)"; fail=1; }
  [ ! -e "$dir/out.png" ] && [ -z "$(ls "$dir" | grep tmp)" ] || { echo "FAIL ($name): a file was left behind"; fail=1; }
  [ $((peak - base)) -le "$growth" ] || { echo "FAIL ($name): resident size grew from $base MB to $peak MB after ${settle} s"; fail=1; }
  [ $fail -eq 0 ] && echo "$name: $seconds s, resident $base -> $peak MB after ${settle} s"
  return $fail
}

# The system's driver and, given SECOND_ICD, the second lavapipe side by side:
# each dispatches at half the pace, and a leak grows by the dispatch.
soak system & first=$!
second=
if [ -n "${SECOND_ICD:-}" ]; then
  soak second-lavapipe VK_DRIVER_FILES="$SECOND_ICD" & second=$!
fi
fail=0
wait $first || fail=1
if [ -n "$second" ]; then wait $second || fail=1; fi
exit $fail
