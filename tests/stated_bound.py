#!/usr/bin/env python3
"""Does a render keep its stated bounds? Per pixel and channel, on colours
clamped to [0,1]:

    |test - ref| <= |test_bound| + |ref_bound| + 1/255

A bound image is grey PFM: a value >= 0 is a stated truncation bound (the exact
colour lies in [value, value + bound]); a negative -e means "no finite bound,
error estimated at e": its magnitude is used, and a pixel that passes only
thanks to such an estimate is counted as "estimate-held", apart.

Two modes:
  stated_bound.py TEST.pfm TEST_BOUND.pfm REF.pfm REF_BOUND.pfm [--name NAME]
  stated_bound.py --snell build/snell --size 64 [--gpu-args "..."] SCENES...
The second renders each scene with the GPU (default settings plus --gpu-args)
and with --cpu (the double-precision reference), both with --bound-image, in a
temporary directory, checks each pair, and prints a summary table.
Exit status 1 if any pixel of any scene violates its bounds (2 on a render failure).
"""
import argparse
import os
import shlex
import subprocess
import sys
import tempfile

import numpy as np

TOLERANCE = 1.0 / 255.0
SHOW = 5  # violating pixels listed per scene


def read_pfm(path):
    """A PFM as a float64 array (rows top to bottom), shape (h, w, 3) or (h, w)."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind not in (b"PF", b"Pf"):
            raise ValueError(f"{path}: not a PFM file")
        dims = f.readline().split()
        while not dims:
            dims = f.readline().split()
        w, h = int(dims[0]), int(dims[1])
        scale = float(f.readline())
        channels = 3 if kind == b"PF" else 1
        data = np.frombuffer(f.read(w * h * channels * 4), dtype="<f4" if scale < 0 else ">f4")
    shape = (h, w, 3) if channels == 3 else (h, w)
    return np.flipud(data.reshape(shape)).astype(np.float64)


def check(test, test_bound, ref, ref_bound):
    """The per-scene result: a dict of counts, worst excess (1/255 units) and the
    first violating pixels as (x from left, y from top)."""
    if test.shape != ref.shape:
        raise ValueError(f"image sizes differ: {test.shape} vs {ref.shape}")
    diff = np.abs(np.clip(test, 0.0, 1.0) - np.clip(ref, 0.0, 1.0))
    diff = np.where(np.isnan(diff), np.inf, diff)  # a NaN colour never holds
    stated = np.abs(test_bound) + np.abs(ref_bound)  # per pixel
    finite = np.where(test_bound >= 0, test_bound, 0.0) + np.where(ref_bound >= 0, ref_bound, 0.0)
    allowed = (stated + TOLERANCE)[..., None]
    excess = (diff - allowed).max(axis=2)  # per pixel, worst channel
    bad = ~(excess <= 0.0)  # NaN bounds count as violations
    held_by_estimate = ~bad & ((diff - (finite + TOLERANCE)[..., None]).max(axis=2) > 0.0)
    ys, xs = np.nonzero(bad)
    worst = np.unravel_index(np.argmax(excess), excess.shape)  # (y, x)
    return {
        "pixels": bad.size,
        "violations": int(bad.sum()),
        "estimate_held": int(held_by_estimate.sum()),
        "estimated": int(((test_bound < 0) | (ref_bound < 0)).sum()),
        "worst": float(excess.max() * 255.0) if bad.any() else 0.0,
        "first": [(int(x), int(y), float(excess[y, x] * 255.0)) for y, x in zip(ys[:SHOW], xs[:SHOW])],
        "worst_at": (int(worst[1]), int(worst[0])),
    }


def report(name, r):
    first = " ".join(f"({x},{y}):+{e:.1f}" for x, y, e in r["first"])
    print(f"{name}: pixels {r['pixels']}, violations {r['violations']}, "
          f"worst excess {r['worst']:.1f}/255, estimate-held {r['estimate_held']} "
          f"(of {r['estimated']} with estimated bounds)" + (f"; worst at {r['worst_at']}; first {first}" if first else ""))


def render(snell, scene, size, extra, out, bound):
    cmd = [snell, "render", scene, "--size", str(size), "-o", out, "--bound-image", bound] + extra
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(map(shlex.quote, cmd))} failed ({done.returncode}):\n{done.stdout}")


def run_scenes(args):
    gpu_args = shlex.split(args.gpu_args)
    rows, failed = [], False
    with tempfile.TemporaryDirectory(prefix="stated_bound.") as tmp:
        for k, scene in enumerate(args.scenes):
            name = os.path.basename(scene)
            f = {s: os.path.join(tmp, f"{k}-{s}.pfm") for s in ("gpu", "gpub", "cpu", "cpub")}
            try:
                render(args.snell, scene, args.size, gpu_args, f["gpu"], f["gpub"])
                render(args.snell, scene, args.size, ["--cpu"] + shlex.split(args.cpu_args), f["cpu"], f["cpub"])
                r = check(read_pfm(f["gpu"]), read_pfm(f["gpub"]), read_pfm(f["cpu"]), read_pfm(f["cpub"]))
            except (RuntimeError, ValueError) as e:
                print(f"{name}: ERROR {e}", file=sys.stderr)
                rows.append((scene, "error", "", ""))
                failed = True
                continue
            report(name, r)
            rows.append((scene, str(r["violations"]), f"{r['worst']:.1f}", str(r["estimate_held"])))
    width = max(len(r[0]) for r in rows) if rows else 5
    print(f"\n{'scene':<{width}}  {'violations':>10}  {'worst/255':>9}  {'est-held':>8}")
    for scene, v, w, e in rows:
        print(f"{scene:<{width}}  {v:>10}  {w:>9}  {e:>8}")
    bad = sum(1 for r in rows if r[1] not in ("0", "error"))
    print(f"{len(rows)} scenes, {bad} with violations" + (", some failed to render" if failed else ""))
    return 2 if failed else (1 if bad else 0)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--snell", help="render SCENES with this snell and check GPU against --cpu")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--gpu-args", default="", help="extra arguments for the GPU render (one string)")
    p.add_argument("--cpu-args", default="", help="extra arguments for the --cpu render (one string)")
    p.add_argument("--name", help="name printed for the four-image mode")
    p.add_argument("files", nargs="*", metavar="SCENES|IMAGES")
    args = p.parse_args()
    if args.snell:
        args.scenes = args.files
        if not args.scenes:
            p.error("no scenes")
        return run_scenes(args)
    if len(args.files) != 4:
        p.error("expected TEST.pfm TEST_BOUND.pfm REF.pfm REF_BOUND.pfm (or --snell ... SCENES)")
    test, test_bound, ref, ref_bound = (read_pfm(f) for f in args.files)
    r = check(test, test_bound, ref, ref_bound)
    report(args.name or os.path.basename(args.files[0]), r)
    return 1 if r["violations"] else 0


if __name__ == "__main__":
    sys.exit(main())
