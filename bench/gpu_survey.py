#!/usr/bin/env python3
"""Survey snell on one Vulkan device: for each scene, the dispatch time of each
traversal (snell's BVH walk against the device's ray queries, runs
interleaved), whether the two images are the same bytes, the SIMD lanes busy,
the parts of a whole command, and the CPU reference's pace beside it.

Written for a real GPU, where the choice between the walk and ray queries is
measured rather than assumed; it runs on lavapipe too. Usage:
  bench/gpu_survey.py [--snell build/snell] [--size 2048] [--runs 5]
                      [--deadline SECONDS] [--out DIR] SCENES...
It prints one markdown table per measure and writes runs.csv under --out.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

FIXED = ["--depth", "64", "--min-weight", "1e-4", "--tolerance", "0"]


def render(snell, scene, size, extra, output):
    """One render; returns its --stats object with the process's wall time added."""
    start = time.monotonic()
    done = subprocess.run([snell, "render", scene, "-s", str(size), "-q", "--stats", "-o", output] + FIXED + extra,
                          capture_output=True, text=True)
    wall = (time.monotonic() - start) * 1e3
    if done.returncode != 0:
        return {"error": (done.stderr.strip() or done.stdout.strip()).splitlines()[-1:], "wall_ms": wall}
    stats = json.loads(done.stdout.strip().splitlines()[-1])
    stats["wall_ms"] = wall
    return stats


def name(scene):
    return scene.replace("../shared/", "").replace("course-scenes/", "course/").replace(".scn", "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--snell", default="build/snell")
    ap.add_argument("--size", type=int, default=2048)
    ap.add_argument("--cpu-size", type=int, default=256, help="image size of the CPU reference's run (0: none)")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--deadline", type=float, default=0, help="start no scene after this many seconds (0: none)")
    ap.add_argument("--out", default=".")
    ap.add_argument("scenes", nargs="+")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    began = time.monotonic()
    rows = []
    tmp = tempfile.mkdtemp()
    images = {t: os.path.join(tmp, t + ".ppm") for t in ("bvh", "ray-query")}
    for scene in a.scenes:
        if a.deadline and time.monotonic() - began > a.deadline:
            print(f"deadline: {name(scene)} and later scenes left out", file=sys.stderr)
            break
        first = render(a.snell, scene, a.size, [], images["bvh"])
        if "error" in first:
            rows.append({"scene": name(scene), "kind": "error", "detail": first["error"]})
            continue
        traversals = ["bvh", "ray-query"] if first["traversal"] != "loop" else ["loop"]
        runs = {t: [] for t in traversals}
        for _ in range(a.runs):
            for t in traversals:
                extra = [] if t == "loop" else ["--traversal", t]
                runs[t].append(render(a.snell, scene, a.size, extra, images.get(t, images["bvh"])))
        same = None
        if len(traversals) == 2 and all("error" not in r[-1] for r in runs.values()):
            same = open(images["bvh"], "rb").read() == open(images["ray-query"], "rb").read()
        for t, rs in runs.items():
            good = [r for r in rs if "error" not in r]
            if not good:
                rows.append({"scene": name(scene), "kind": t, "detail": rs[0]["error"]})
                continue
            med = lambda key: statistics.median(r[key] for r in good)
            rows.append({
                "scene": name(scene), "kind": t, "device": good[0]["device"], "size": a.size,
                "render_ms": med("render_ms"), "render_min_ms": min(r["render_ms"] for r in good),
                "rays": good[0]["rays"]["total"], "upload_ms": med("upload_ms"), "pipeline_ms": med("pipeline_ms"),
                "readback_ms": med("readback_ms"), "write_wait_ms": med("write_wait_ms"), "total_ms": med("total_ms"),
                "wall_ms": med("wall_ms"), "same_image": same, "runs": len(good)})
        counted = render(a.snell, scene, a.size, ["--count-lanes"] + (["--traversal", "bvh"] if len(traversals) == 2 else []),
                         images["bvh"])
        if "lanes" in counted:
            rows.append({"scene": name(scene), "kind": "lanes", **counted["lanes"]})
        if a.cpu_size:
            cpu = render(a.snell, scene, a.cpu_size, ["--cpu"], images["bvh"])
            if "error" not in cpu:
                rows.append({"scene": name(scene), "kind": "cpu", "size": a.cpu_size, "render_ms": cpu["render_ms"],
                             "rays": cpu["rays"]["total"]})
        print(f"{time.monotonic() - began:6.1f} s  {name(scene)}", file=sys.stderr, flush=True)

    keys = sorted({k for r in rows for k in r})
    with open(os.path.join(a.out, "runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)

    by = {}
    for r in rows:
        by.setdefault(r["scene"], {})[r["kind"]] = r
    mrays = lambda r: r["rays"] / r["render_ms"] / 1e3 if r.get("render_ms") else 0
    print(f"\n| scene | traversal | dispatch ms (median / min) | Mrays/s | CPU Mrays/s | GPU/CPU | same bytes |")
    print("|---|---|---|---|---|---|---|")
    for scene, kinds in by.items():
        cpu = kinds.get("cpu")
        for t in ("loop", "bvh", "ray-query"):
            r = kinds.get(t)
            if not r:
                continue
            if "render_ms" not in r:
                print(f"| {scene} | {t} | error: {r.get('detail')} | | | | |")
                continue
            ratio = f"{mrays(r) / mrays(cpu):.1f}×" if cpu and mrays(cpu) else ""
            print(f"| {scene} | {t} | {r['render_ms']:.2f} / {r['render_min_ms']:.2f} | {mrays(r):.0f} | "
                  f"{mrays(cpu) if cpu else 0:.1f} | {ratio} | {'' if r['same_image'] is None else r['same_image']} |")
    print("\n| scene | trace loop busy | BVH walk busy |\n|---|---|---|")
    for scene, kinds in by.items():
        l = kinds.get("lanes")
        if l:
            walk = f"{100 * l['walk_occupancy']:.1f} %" if l["walk_slots"] else "(no BVH)"
            print(f"| {scene} | {100 * l['trace_occupancy']:.1f} % | {walk} |")
    print("\n| scene | upload | pipeline | dispatch | readback | write wait | total | process |\n|---|---|---|---|---|---|---|---|")
    for scene, kinds in by.items():
        r = kinds.get("loop") or kinds.get("bvh")
        if r and "total_ms" in r:
            print(f"| {scene} | {r['upload_ms']:.1f} | {r['pipeline_ms']:.1f} | {r['render_ms']:.1f} | "
                  f"{r['readback_ms']:.1f} | {r['write_wait_ms']:.1f} | {r['total_ms']:.1f} | {r['wall_ms']:.0f} |")


if __name__ == "__main__":
    main()
