#!/usr/bin/env bash
# Lane occupancy: for each scene, the share of SIMD lane slots that do useful
# work in the trace loop and in the BVH walk (render --count-lanes), next to
# rays a second from a plain render (counting costs time). Usage:
#   bench/lanes.sh [SNELL] [SIZE] SCENES... > lanes.md
set -euo pipefail
snell=${1:-build/snell}; size=${2:-128}; shift 2 || true
[ $# -gt 0 ] || set -- scenes/*.scn scenes/hard/*.scn ../shared/course-scenes/*.scn ../shared/bench-scenes/*.scn
echo "| scene | Mrays/s | trace loop busy | BVH walk busy |"
echo "|---|---|---|---|"
for scene in "$@"; do
  plain=$("$snell" render "$scene" --size "$size" -q --stats -o /tmp/snell-lanes.png | tail -n 1)
  counted=$("$snell" render "$scene" --size "$size" -q --stats --count-lanes -o /tmp/snell-lanes.png | tail -n 1)
  python3 - "$scene" "$plain" "$counted" <<'PY'
import json, sys
scene, plain, counted = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3])
lanes = counted["lanes"]
rate = plain["rays"]["total"] / plain["render_ms"] / 1e3 if plain["render_ms"] > 0 else 0
walk = f'{100 * lanes["walk_occupancy"]:.1f} %' if lanes["walk_slots"] else "(no BVH)"
name = scene.replace("../shared/", "").replace("course-scenes/", "course/").replace(".scn", "")
print(f'| {name} | {rate:.1f} | {100 * lanes["trace_occupancy"]:.1f} % | {walk} |')
PY
done
rm -f /tmp/snell-lanes.png
