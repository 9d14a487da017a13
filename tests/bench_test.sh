#!/usr/bin/env bash
# `snell bench --quick` works and its numbers are sane; never a timing asserted.
# BENCH_PART=quick (the default): the quick run as a user types it, the
# bench scenes simple and grid with their peers and the scaling curve: the
# CSV and JSON, bench.md and the plot written by the bench itself, the
# summary table it ends with; every setting rendered with a positive time and
# finite error, the default within 0.5/255 of the exact image; each scene's
# price of the default (finite and positive, or flagged an upper bound) set
# by a fixed tree of the front; CPU times as medians of several runs; the
# walk's floor on the BVH scene; the peers tracing one tree (POV-Ray's
# max_trace_level one more than snell's depth), POV-Ray's trace ratio only
# as precise as its whole milliseconds, and its image held to snell's on the
# opaque scene (it and the CPU reference's) and not on the glass one (saying
# why).
# BENCH_PART=no-scaling: one scene given, --no-scaling: that scene alone, no
# scaling curve, no peers.
set -u
: "${SNELL:?}" "${SOURCE:?}" "${PYTHON:=python3}"
part=${BENCH_PART:-quick}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

case "$part" in
  quick) args=() ;;
  no-scaling) args=(--no-scaling "$SOURCE/scenes/basic.scn") ;;
  *) fail "BENCH_PART=$part is not quick or no-scaling" ;;
esac
"$SNELL" bench --quick --source-dir "$SOURCE" -o "$out" "${args[@]}" >"$out/summary" 2>"$out/log"; status=$?
cat "$out/log" "$out/summary"
[ $status -eq 0 ] || fail "bench exited with $status"
for f in bench.csv bench.json bench.md; do [ -s "$out/$f" ] || fail "no $f"; done
# The plot, drawn by the bench where a python3 it finds has matplotlib.
if python3 -c 'import matplotlib' 2>/dev/null || /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  [ "$(head -c 4 "$out/bench.png" | od -An -c | tr -d ' ')" = "211PNG" ] || fail "no plot"
else
  grep -q "^snell: warning: no plot: " "$out/log" || fail "no plot and no warning saying why"
fi
grep -q "^| scene | default ms | price of the default" "$out/bench.md" || fail "no price table in bench.md"
# The summary on standard output: a row per scene, the price summary last.
grep -q "^scene  *default ms  *mean error  *price  *CPU ms (runs)  *GPU faster" "$out/summary" ||
  fail "no summary table on standard output"
tail -n 1 "$out/summary" | grep -q "^price of the default: geometric mean " || fail "the summary does not end with the price"

"$PYTHON" - "$out" "$part" <<'PY' || exit 1
import csv, json, math, os, re, sys
out, part = sys.argv[1], sys.argv[2]
d = json.load(open(os.path.join(out, "bench.json")))
summary = open(os.path.join(out, "summary")).read()
fail = []
if not d["ceiling_tests_per_s"]["centre_radius"] > 0: fail.append("no ceiling")
if not (d["floor"]["store_kernel_ms"] > 0 and d["floor"]["empty_scene_ms"] > 0): fail.append("no floor")
if "Mesa" not in d["driver"] and "llvmpipe" in d["device"]: fail.append(f"driver not named: {d['driver']}")
rows = list(csv.DictReader(open(os.path.join(out, "bench.csv"))))
if len(rows) != len(d["results"]): fail.append("CSV and JSON disagree")
scenes = {r["scene"] for r in d["results"]}
expected = {"bench/simple", "bench/grid"} if part == "quick" else {"scenes/basic"}
if scenes != expected: fail.append(f"scenes {sorted(scenes)}, not {sorted(expected)}")
for r in d["results"]:
    name = f'{r["scene"]} [{r["setting"]}]'
    if r["failure"]: fail.append(f"{name}: {r['failure']}"); continue
    t = r["dispatch_ms"]
    if not (0 < t["min"] <= t["median"] <= t["max"]): fail.append(f"{name}: times {t}")
    if r["rays"]["primary"] <= 0: fail.append(f"{name}: no primary rays")
    if r["error"]["non_finite"]: fail.append(f"{name}: NaN/Inf pixels")
    if r["setting"] == "default" and r["error"]["mean_abs_error"] > 0.5:
        fail.append(f"{name}: default error {r['error']['mean_abs_error']} > 0.5/255")
    # The CPU reference timed as the GPU is: a median of several runs (or one
    # render long enough to time alone), never a single cold millisecond.
    for key in ("reference", "cpu_default"):
        ms, runs = r[f"{key}_ms"], r[f"{key}_runs"]
        if not (ms > 0 and (runs >= 5 or (runs == 1 and ms >= 500))): fail.append(f"{name}: {key} {ms} ms of {runs} runs")
    if r["scene"] + " " not in summary and r["setting"] == "default": fail.append(f"{r['scene']}: no summary row")
# The price of the default, per scene: its time over the fastest fixed tree's
# as accurate, or (flagged) an upper bound where no fixed tree tried was.
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
    # Timed again side by side (the two settings in turn), so its times are its own.
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

if part == "no-scaling":
    if d["scaling"] or d["peers"]: fail.append(f"--no-scaling: scaling {d['scaling']}, peers {d['peers']}")
else:
    if [s["spheres"] for s in d["scaling"]] != [10, 1000]: fail.append(f"scaling counts {d['scaling']}")
    for s in d["scaling"]:
        if not s["render_ms"]["median"] > 0: fail.append(f"scaling {s}")
    # The walk's floor on the BVH scene, casting the renderer's rays: some
    # camera rays miss, some shadow rays are blocked, not all.
    floors = {w["scene"]: w for w in d["walk_floors"]}
    w = floors.get("bench/grid")
    if not w: fail.append("no walk floor for bench/grid")
    elif not (w["floor_kernel_ms"] > 0 and w["render_depth0_ms"] > 0
              and 0 < w["floor_kernel_hits"] < w["size"] ** 2
              and 0 < w["floor_kernel_blocked"] < w["floor_kernel_rays"] - w["size"] ** 2
              and abs(w["floor_kernel_rays"] - w["render_depth0_rays"]) <= 1e-3 * w["render_depth0_rays"]):
        fail.append(f"walk floor {w}")
    peers = {p["scene"]: p for p in d["peers"]}
    if set(peers) != scenes: fail.append(f"peers {sorted(peers)}")
    for name, p in peers.items():
        if not (p["snell_dispatch_ms"] > 0 and p["snell_command_ms"] > 0 and p["cpu_reference_ms"] > 0
                and p["cpu_reference_runs"] >= 5):
            fail.append(f"peer {p}")
        # One tree: POV-Ray counts the camera ray as a level.
        if p["povray_max_trace_level"] != p["depth"] + 1 or p["samples_per_pixel"] != 1:
            fail.append(f"{name}: depth {p['depth']} against max_trace_level {p['povray_max_trace_level']}")
        pov = open(os.path.join(out, name.split("/")[1] + ".pov")).read()
        if f"max_trace_level {p['depth'] + 1} " not in pov: fail.append(f"{name}: the POV-Ray scene's trace level")
        if p["povray_trace_ms"] is None: fail.append(f"{name}: POV-Ray did not run: {p['note']}"); continue
        # POV-Ray prints whole ms: a trace of a few ms gives its ratio as a range.
        if p["povray_trace_resolution_ms"] != 1: fail.append(f"{name}: resolution {p['povray_trace_resolution_ms']}")
        row = next((l for l in summary.splitlines() if l.startswith(name + " ") and "(to " in l), "")
        m = re.search(r"\(to \S+\)\s+(below \S+|\S+)x ", row)
        digits = m and len(m.group(1).replace(".", "").lstrip("0"))
        if not m or (p["povray_trace_ms"] < 50 and "-" not in m.group(1) and "below" not in m.group(1) and digits > 2):
            fail.append(f"{name}: the trace ratio claims more digits than {p['povray_trace_ms']} ms allow: {row!r}")
    # POV-Ray's image against snell's: held to it on the opaque scene, not on
    # glass. Against the CPU reference (double) to 1/255 where no ray grazes
    # a sphere; the GPU's fp32 may part from both on a grazing ray or two.
    a = peers.get("bench/grid", {}).get("povray_agreement", {})
    if not (a.get("compared") and a["cpu_reference_error"]["mean_abs_error"] <= 0.1
            and a["cpu_reference_error"]["bad_fraction"] <= 0.001
            and a["error"]["mean_abs_error"] <= 0.5 and a["error"]["bad_fraction"] <= 0.01):
        fail.append(f"bench/grid: POV-Ray's image against snell's: {a}")
    a = peers.get("bench/simple", {}).get("povray_agreement", {})
    if a.get("compared") or "transparent" not in a.get("note", ""): fail.append(f"bench/simple: {a}")
for f in fail: print("FAIL:", f)
print(f"bench: {len(d['results'])} settings checked, {len(fail)} problems")
sys.exit(1 if fail else 0)
PY
