#!/usr/bin/env bash
# `snell bench --quick` works and its numbers are sane: the CSV and JSON are
# written; every setting rendered, with a positive time and finite error; the
# default settings stay within 0.5/255 of the exact image; every scene has a
# price of the default (finite and positive, or flagged an upper bound) set by
# a fixed tree of the front, and the summary its geometric mean; the ceiling,
# the floor, the walk's floor on the BVH scenes (casting the renderer's
# rays), the peers and the scaling curve are there; bench/summarize.py
# makes its tables and plot from them. Not a timed test.
# BENCH_PART runs one part, so the parts run side by side: "scenes:K/N" or
# "bench:K/N" (the K-th of N shares of scenes/ or of the bench scenes, dealt
# round and linked into a folder of the same name, which the bench groups as
# it groups the folder: the bench scenes with their peers), or "scaling" (one
# scene and the scaling curve; then --no-scaling); by default all of it.
set -u
: "${SNELL:?}" "${SOURCE:?}" "${PYTHON:=python3}"
part=${BENCH_PART:-all}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
what=()
names=()  # the scenes of this part, as the bench names them
case "$part" in
  all) ;;
  scaling) what=("$SOURCE/scenes/basic.scn") ;;
  scenes:*/* | bench:*/*)
    kind=${part%%:*} share=${part#*:}
    k=${share%/*} n=${share#*/}
    if [ "$kind" = scenes ]; then from="$SOURCE/scenes" folder=scenes; else from="$SOURCE/../shared/bench-scenes" folder=bench-scenes; fi
    mkdir -p "$out/in/$folder"
    i=0
    for f in "$from"/*.scn; do
      if [ $((i % n + 1)) -eq "$k" ]; then
        ln -s "$f" "$out/in/$folder/" && names+=("$kind/$(basename "$f" .scn)")
      fi
      i=$((i + 1))
    done
    [ ${#names[@]} -gt 0 ] || { echo "FAIL: BENCH_PART=$part chooses no scene"; exit 1; }
    what=(--no-scaling "$out/in/$folder") ;;
  *) echo "FAIL: BENCH_PART=$part is not all, scenes:K/N, bench:K/N or scaling"; exit 1 ;;
esac
has() { [ "$part" = all ] || printf '%s\n' "${names[@]}" | grep -qx "$1"; }
"$SNELL" bench --quick --source-dir "$SOURCE" -o "$out" "${what[@]}" 2>"$out/log"; status=$?
cat "$out/log"
[ $status -eq 0 ] || { echo "FAIL: bench exited with $status"; exit 1; }
for f in bench.csv bench.json; do [ -s "$out/$f" ] || { echo "FAIL: no $f"; exit 1; }; done
"$PYTHON" "$SOURCE/bench/summarize.py" "$out/bench.json" --plot "$out/bench.png" >"$out/tables.md" ||
  { echo "FAIL: bench/summarize.py"; exit 1; }
[ "$(head -c 4 "$out/bench.png" | od -An -c | tr -d ' ')" = "211PNG" ] || { echo "FAIL: no plot"; exit 1; }
if has bench/simple; then
  grep -q "^| bench/simple" "$out/tables.md" || { echo "FAIL: no table row for bench/simple"; exit 1; }
fi
grep -q "^| scene | default ms | price of the default" "$out/tables.md" || { echo "FAIL: no price table"; exit 1; }
if has scenes/grid || has bench/grid; then
  grep -q "^| BVH scene (depth 0) | size | walk's floor ms" "$out/tables.md" || { echo "FAIL: no walk floor table"; exit 1; }
fi
grep -q "^Price of the default: geometric mean" "$out/tables.md" || { echo "FAIL: no price summary"; exit 1; }
grep -q "^price of the default: geometric mean" "$out/log" || { echo "FAIL: no price summary in the log"; exit 1; }
"$PYTHON" - "$out" "$part" "${names[@]}" <<'PY'
import csv, json, sys, os
out, part, names = sys.argv[1], sys.argv[2], set(sys.argv[3:])
d = json.load(open(os.path.join(out, "bench.json")))
fail = []
if not d["ceiling_tests_per_s"]["centre_radius"] > 0: fail.append("no ceiling")
if not (d["floor"]["store_kernel_ms"] > 0 and d["floor"]["empty_scene_ms"] > 0): fail.append("no floor")
if "Mesa" not in d["driver"] and "llvmpipe" in d["device"]: fail.append(f"driver not named: {d['driver']}")
rows = list(csv.DictReader(open(os.path.join(out, "bench.csv"))))
if len(rows) != len(d["results"]): fail.append("CSV and JSON disagree")
for r in d["results"]:
    name = f'{r["scene"]} [{r["setting"]}]'
    if r["failure"]: fail.append(f"{name}: {r['failure']}"); continue
    t = r["dispatch_ms"]
    if not (0 < t["min"] <= t["median"] <= t["max"]): fail.append(f"{name}: times {t}")
    if r["rays"]["primary"] <= 0: fail.append(f"{name}: no primary rays")
    if r["error"]["non_finite"]: fail.append(f"{name}: NaN/Inf pixels")
    if r["setting"] == "default" and r["error"]["mean_abs_error"] > 0.5:
        fail.append(f"{name}: default error {r['error']['mean_abs_error']} > 0.5/255")
    if not r["cpu_default_ms"] > 0: fail.append(f"{name}: no CPU time at the same settings")
scenes = {r["scene"] for r in d["results"]}
if part == "all":
    if not any(s.startswith("scenes/") for s in scenes): fail.append("no scenes/ scenes")
    if not any(s.startswith("bench/") for s in scenes): fail.append("no bench scenes")
elif names and scenes != names: fail.append(f"scenes {sorted(scenes)}, the part's {sorted(names)}")
if (part == "all" or any(n.startswith("bench/") for n in names)) and not d["peers"]:
    fail.append("no peers (../shared/bench-scenes)")
for p in d["peers"]:
    if not (p["snell_dispatch_ms"] > 0 and p["snell_command_ms"] > 0 and p["cpu_reference_ms"] > 0):
        fail.append(f"peer {p}")
# The walk's floor on each BVH scene: the renderer's walk alone, casting the
# renderer's rays (the same camera and shadow rays, as counted).
floors = {w["scene"] for w in d.get("walk_floors", [])}
for need in ("scenes/grid", "bench/grid") if part == "all" else [n for n in names if n.endswith("/grid")]:
    if need not in floors: fail.append(f"no walk floor for {need}")
for w in d.get("walk_floors", []):
    if not (w["floor_kernel_ms"] > 0 and w["render_depth0_ms"] > 0): fail.append(f"walk floor {w}")
    # Both grids show background and cast shadows on each other: some
    # camera rays miss, some shadow rays are blocked, not all.
    shadow = w["floor_kernel_rays"] - w["size"] ** 2
    if not 0 < w["floor_kernel_hits"] < w["size"] ** 2: fail.append(f"walk floor {w['scene']}: hits {w}")
    if not 0 < w["floor_kernel_blocked"] < shadow: fail.append(f"walk floor {w['scene']}: blocked {w}")
    if abs(w["floor_kernel_rays"] - w["render_depth0_rays"]) > 1e-3 * w["render_depth0_rays"]:
        fail.append(f"walk floor {w['scene']}: {w['floor_kernel_rays']} rays, the renderer {w['render_depth0_rays']}")
if part in ("all", "scaling") and [s["spheres"] for s in d["scaling"]] != [10, 100, 1000, 10000]:
    fail.append("scaling counts")
if part not in ("all", "scaling") and d["scaling"]: fail.append("a scaling curve under --no-scaling")
for s in d["scaling"]:
    if not s["render_ms"]["median"] > 0: fail.append(f"scaling {s}")
# The price of the default, per scene: its time over the fastest fixed tree's
# as accurate, or (flagged) an upper bound where no fixed tree tried was.
import math
settings = {(r["scene"], r["setting"]): r for r in d["results"]}
prices = {p["scene"]: p for p in d["prices"]}
if set(prices) != scenes: fail.append(f"prices for {sorted(prices)}, scenes {sorted(scenes)}")
for scene, p in prices.items():
    price = p["price"]
    if not (price is not None and math.isfinite(price) and price > 0):
        if not p["price_is_upper_bound"]: fail.append(f"{scene}: price {price}, not an upper bound")
        continue
    fixed = settings.get((scene, p["fixed_setting"]))
    if not fixed or not fixed["front"] or fixed["tolerance"] != 0:
        fail.append(f"{scene}: price set by {p['fixed_setting']!r}, not a fixed tree of the front"); continue
    default = settings[(scene, "default")]
    # Timed again side by side (the two settings in turn), so its times are
    # its own, not the sweep's.
    if abs(price - p["default_ms"] / p["fixed_ms"]) > 1e-3 * price:
        fail.append(f"{scene}: price {price} is not default/fixed time")
    if p["side_by_side_runs"] < 5: fail.append(f"{scene}: price from {p['side_by_side_runs']} runs side by side")
    as_accurate = (fixed["error"]["mean_abs_error"] <= default["error"]["mean_abs_error"]
                   and fixed["error"]["bad_pixels"] <= default["error"]["bad_pixels"])
    if as_accurate == p["price_is_upper_bound"]:
        fail.append(f"{scene}: {p['fixed_setting']} as accurate: {as_accurate}, upper bound: {p['price_is_upper_bound']}")
    n = p["pixels"]
    if n["total"] != d["size"] ** 2 or n["certified"] + n["estimated"] > n["total"]:
        fail.append(f"{scene}: pixel counts {n}")
    if not any(r["front"] for (s, _), r in settings.items() if s == scene): fail.append(f"{scene}: no fixed trees")
s = d["price_summary"]
if not (s["geometric_mean"] is not None and math.isfinite(s["geometric_mean"]) and s["geometric_mean"] > 0):
    fail.append(f"price summary {s}")
elif s["worst_scene"] not in prices: fail.append(f"worst scene {s['worst_scene']}")
for f in fail: print("FAIL:", f)
print(f"bench: {len(d['results'])} settings checked, {len(fail)} problems")
sys.exit(1 if fail else 0)
PY
status=$?
[ "$part" = all ] || [ "$part" = scaling ] || exit $status
# --no-scaling: the scenes given, and no scaling curve.
"$SNELL" bench --quick --no-scaling --source-dir "$SOURCE" -o "$out/one" "$SOURCE/scenes/basic.scn" 2>"$out/one.log" ||
  { cat "$out/one.log"; echo "FAIL: bench --no-scaling"; exit 1; }
"$PYTHON" -c '
import json, sys
d = json.load(open(sys.argv[1]))
scenes = {r["scene"] for r in d["results"]}
sys.exit(0 if d["scaling"] == [] and len(scenes) == 1 else "FAIL: --no-scaling: %s, scenes %s" % (d["scaling"], scenes))
' "$out/one/bench.json" || exit 1
exit $status
