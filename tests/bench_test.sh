#!/usr/bin/env bash
# `snell bench --quick` works and its numbers are sane: the CSV and JSON are
# written; every setting rendered, with a positive time and finite error; the
# default settings stay within 0.5/255 of the exact image; the ceiling, the
# floor, the peers and the scaling curve are there; bench/summarize.py makes
# its tables and plot from them. Not a timed test.
set -u
: "${SNELL:?}" "${SOURCE:?}" "${PYTHON:=python3}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$SNELL" bench --quick --source-dir "$SOURCE" -o "$out" 2>"$out/log"; status=$?
cat "$out/log"
[ $status -eq 0 ] || { echo "FAIL: bench exited with $status"; exit 1; }
for f in bench.csv bench.json; do [ -s "$out/$f" ] || { echo "FAIL: no $f"; exit 1; }; done
"$PYTHON" "$SOURCE/bench/summarize.py" "$out/bench.json" --plot "$out/bench.png" >"$out/tables.md" ||
  { echo "FAIL: bench/summarize.py"; exit 1; }
[ "$(head -c 4 "$out/bench.png" | od -An -c | tr -d ' ')" = "211PNG" ] || { echo "FAIL: no plot"; exit 1; }
grep -q "^| bench/simple" "$out/tables.md" || { echo "FAIL: no table row for bench/simple"; exit 1; }
"$PYTHON" - "$out" <<'PY'
import csv, json, sys, os
out = sys.argv[1]
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
if not any(s.startswith("scenes/") for s in scenes): fail.append("no scenes/ scenes")
if not d["peers"]: fail.append("no peers (../shared/bench-scenes)")
for p in d["peers"]:
    if not (p["snell_dispatch_ms"] > 0 and p["snell_command_ms"] > 0 and p["cpu_reference_ms"] > 0):
        fail.append(f"peer {p}")
if [s["spheres"] for s in d["scaling"]] != [10, 100, 1000, 10000]: fail.append("scaling counts")
for s in d["scaling"]:
    if not s["render_ms"]["median"] > 0: fail.append(f"scaling {s}")
for f in fail: print("FAIL:", f)
print(f"bench: {len(d['results'])} settings checked, {len(fail)} problems")
sys.exit(1 if fail else 0)
PY
