#!/usr/bin/env python3
"""Markdown tables from `snell bench`'s bench.json, as the README shows them:
python3 bench/summarize.py bench/results/bench.json"""
import json
import sys


def ms(v):
    return "–" if v is None else (f"{v:.0f}" if v >= 100 else f"{v:.1f}" if v >= 10 else f"{v:.2f}")


def main() -> None:
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = json.load(open(sys.argv[1]))
    results = [r for r in d["results"] if not r["failure"]]
    by = {}
    for r in results:
        by.setdefault(r["scene"], {})[r["setting"]] = r
    print(f"Device: {d['device']}; {d['size']}×{d['size']}, median of {d['runs']} runs ({d['timing']}).\n")

    print("| scene | spheres | default ms | Mrays/s | mean error | max | best setting within 0.5/255 | its ms | fp64 ms | fp64 error |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for scene, settings in by.items():
        de = settings.get("default")
        if not de:
            continue
        rays = sum(de["rays"].values())
        good = [r for r in settings.values() if r["error"]["mean_abs_error"] <= 0.5]
        best = min(good, key=lambda r: r["dispatch_ms"]["median"]) if good else None
        f = settings.get("fp64")
        print(f"| {scene} | {de['spheres']} | {ms(de['dispatch_ms']['median'])} | "
              f"{rays / de['dispatch_ms']['median'] / 1e3:.1f} | {de['error']['mean_abs_error']:.3f} | "
              f"{de['error']['max_error']} | {best['setting'] if best else '–'} | "
              f"{ms(best['dispatch_ms']['median']) if best else '–'} | "
              f"{ms(f['dispatch_ms']['median']) if f else '–'} | "
              f"{f['error']['mean_abs_error']:.3f} |" if f else "–")

    print("\n| hard case | fp32 mean | fp32 max | fp32 bad % | fp32 ms | fp64 mean | fp64 max | fp64 bad % | fp64 ms |")
    print("|---|---|---|---|---|---|---|---|---|")
    for scene, settings in by.items():
        if not scene.startswith("hard/") or "default" not in settings or "fp64" not in settings:
            continue
        a, b = settings["default"], settings["fp64"]
        print(f"| {scene[5:]} | {a['error']['mean_abs_error']:.3f} | {a['error']['max_error']} | "
              f"{100 * a['error']['bad_fraction']:.3f} | {ms(a['dispatch_ms']['median'])} | "
              f"{b['error']['mean_abs_error']:.3f} | {b['error']['max_error']} | "
              f"{100 * b['error']['bad_fraction']:.3f} | {ms(b['dispatch_ms']['median'])} |")

    if d["peers"]:
        print("\n| bench scene | size | snell dispatch ms | snell command ms | first image cold / warm ms | CPU reference ms | POV-Ray trace ms | POV-Ray command ms | trace ratio | command ratio |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for p in d["peers"]:
            pt, pc = p["povray_trace_ms"], p["povray_command_ms"]
            trace_ratio = "–" if pt is None else f"{pt / p['snell_dispatch_ms']:.2f}×"
            command_ratio = "–" if pc is None else f"{pc / p['snell_command_ms']:.2f}×"
            print(f"| {p['scene']} | {p['size']}² | {ms(p['snell_dispatch_ms'])} | {ms(p['snell_command_ms'])} | "
                  f"{ms(p['first_image_cold_ms'])} / {ms(p['first_image_warm_ms'])} | {ms(p['cpu_reference_ms'])} | "
                  f"{ms(pt)} | {ms(pc)} | "
                  f"{trace_ratio} | {command_ratio} |")

    if d["scaling"]:
        print("\n| spheres | parse ms | BVH build ms | render ms (median, min–max) | scene on the GPU MiB | peak RSS MiB |")
        print("|---|---|---|---|---|---|")
        for s in d["scaling"]:
            r = s["render_ms"]
            print(f"| {s['spheres']:,} | {ms(s['parse_ms'])} | {ms(s['bvh_build_ms'])} | "
                  f"{ms(r['median'])} ({ms(r['min'])}–{ms(r['max'])}) at {s['size']}² | {s['gpu_scene_mib']:.2f} | "
                  f"{s['peak_rss_mib']:.0f} |")
    c = d["ceiling_tests_per_s"]
    print(f"\nCeiling (micro-kernel, one ray against 64 spheres): {c['centre_radius'] / 1e9:.2f} G tests/s "
          f"centre+radius, {c['inverse_matrix'] / 1e9:.2f} G inverse matrix.")


if __name__ == "__main__":
    main()
