#!/usr/bin/env python3
"""Tables and a plot from `snell bench`'s bench.json.

    python3 bench/summarize.py bench/results/bench.json [--plot bench/results/bench.png]

prints the Markdown tables of docs/log/benchmark.md (with the price of the
default: its time over that of the fastest fixed tree as accurate) and, with --plot, draws
speed against error: a panel per scene, dispatch time (ms) against the mean
error (in 1/255) of each setting measured against the limit reference (dots,
each named, the default ringed; the fixed trees the default is priced against
in red, their Pareto front drawn) and against the mean
error the render itself guarantees, its stated truncation bound (triangles;
none where the scene's bound is not finite) (matplotlib, Debian's
python3-matplotlib)."""
import argparse
import json
import math


def ms(v):
    return "–" if v is None else (f"{v:.0f}" if v >= 100 else f"{v:.1f}" if v >= 10 else f"{v:.2f}")


def tables(d):
    results = [r for r in d["results"] if not r["failure"]]
    by = {}
    for r in results:
        by.setdefault(r["scene"], {})[r["setting"]] = r
    print(f"Device: {d['device']}; {d['size']}×{d['size']}, median of {d['runs']} runs ({d['timing']}).\n")

    print("| scene | spheres | default ms | Mrays/s | mean error | max | stated bound mean / max | "
          "CPU reference ms, same settings | GPU faster | best setting within 0.5/255 | its ms | fp64 ms | fp64 error |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for scene, settings in by.items():
        de = settings.get("default")
        if not de:
            continue
        rays = sum(de["rays"].values())
        good = [r for r in settings.values() if r["error"]["mean_abs_error"] <= 0.5]
        best = min(good, key=lambda r: r["dispatch_ms"]["median"]) if good else None
        f = settings.get("fp64")
        cpu = de.get("cpu_default_ms")
        gpu = de["dispatch_ms"]["median"]
        faster = "–" if cpu is None else f"{cpu / gpu:.1f}×"
        sb = de.get("stated_bound", {})
        bound = (f"{sb['mean']:.3f} / {sb['max']:.2f}" + (f" ({sb['unbounded_pixels']} unbounded)"
                 if sb.get("unbounded_pixels") else "")) if sb else "–"
        print(f"| {scene} | {de['spheres']} | {ms(gpu)} | {rays / gpu / 1e3:.1f} | "
              f"{de['error']['mean_abs_error']:.3f} | {de['error']['max_error']} | {bound} | {ms(cpu)} | {faster} | "
              f"{best['setting'] if best else '–'} | {ms(best['dispatch_ms']['median']) if best else '–'} | "
              f"{ms(f['dispatch_ms']['median']) if f else '–'} | "
              f"{(format(f['error']['mean_abs_error'], '.3f')) if f else '–'} |")

    prices(d)

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
        peers(d["peers"])

    if d.get("walk_floors"):
        print("\n| BVH scene (depth 0) | size | walk's floor ms | Mrays/s | renderer ms | Mrays/s | renderer / floor |")
        print("|---|---|---|---|---|---|---|")
        for w in d["walk_floors"]:
            f, r = w["floor_kernel_ms"], w["render_depth0_ms"]
            print(f"| {w['scene']} | {w['size']}² | {ms(f)} | {w['floor_kernel_rays'] / f / 1e3:.1f} | {ms(r)} | "
                  f"{w['render_depth0_rays'] / r / 1e3:.1f} | {r / f:.2f}× |")

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
    f = d.get("floor")
    if f:
        print(f"Floor at {f['size']}²: a kernel that only stores each pixel {ms(f['store_kernel_ms'])} ms; "
              f"the renderer on an empty scene {ms(f['empty_scene_ms'])} ms "
              f"({f['empty_scene_ms'] / f['store_kernel_ms']:.1f}×).")


def ratio(a, half_step, b):
    """a / b where a is known only to ±half_step (POV-Ray prints its trace time in whole ms): to three digits,
    or two, where the step allows them, else the range it leaves (as snell bench's log)."""
    if a is None or not b:
        return "–"

    def digits(v, n):  # n significant digits, trailing zeros kept
        return f"{v:.{max(0, n - 1 - math.floor(math.log10(v))) if v > 0 else n}f}"

    u = half_step / a if a > 0 else math.inf
    if u <= 5e-3:
        return digits(a / b, 3 if u <= 5e-4 else 2) + "×"
    low, high = digits(max(0.0, a - half_step) / b, 2), digits((a + half_step) / b, 2)
    if a <= half_step:
        return f"below {high}×"
    return f"{high}×" if low == high else f"{low}–{high}×"


def agreement(p):
    """POV-Ray's image against snell's, where the two models agree (opaque spheres)."""
    a = p.get("povray_agreement")
    if not a:
        return "–"
    if not a["compared"]:
        return a["note"]
    e, c = a["error"], a["cpu_reference_error"]
    text = (f"mean {e['mean_abs_error']:.3f}/255, max {e['max_error']}/255, {100 * e['bad_fraction']:.2f} % over "
            f"3/255: {'agrees' if a['agrees'] else 'differs'} (the CPU reference's: mean "
            f"{c['mean_abs_error']:.3f}/255, max {c['max_error']}/255)")
    return text + (f"; {a['note']}" if a["note"] else "")


def peers(rows):
    """The peers on the bench scenes: the same tree in each (snell's depth, POV-Ray's max_trace_level one more)."""
    print("\n| bench scene | size | depth / POV-Ray level | snell dispatch ms | snell command ms | "
          "first image cold / warm ms | CPU reference ms | POV-Ray trace ms | POV-Ray command ms | trace ratio | "
          "command ratio | POV-Ray's image against snell's |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for p in rows:
        pt, pc = p["povray_trace_ms"], p["povray_command_ms"]
        step = p.get("povray_trace_resolution_ms", 1.0) or 0.0  # POV-Ray prints whole ms
        command_ratio = "–" if pc is None else f"{pc / p['snell_command_ms']:.2f}×"
        level = f"{p['depth']} / {p['povray_max_trace_level']}" if "depth" in p else "5 / 5"
        trace = "–" if pt is None else f"{pt:g}" + (f" (to {step:g})" if step else "")
        print(f"| {p['scene']} | {p['size']}² | {level} | {ms(p['snell_dispatch_ms'])} | "
              f"{ms(p['snell_command_ms'])} | {ms(p['first_image_cold_ms'])} / {ms(p['first_image_warm_ms'])} | "
              f"{ms(p['cpu_reference_ms'])} | {trace} | {ms(pc)} | {ratio(pt, step / 2, p['snell_dispatch_ms'])} | "
              f"{command_ratio} | {agreement(p)} |")


def price(p):
    """The price of the default as printed: "1.23×", or "< 0.85×" where no fixed tree tried was as accurate."""
    if p.get("price") is None:
        return "–"
    return ("< " if p["price_is_upper_bound"] else "") + f"{p['price']:.3g}×"


def prices(d):
    """The price of the default: its dispatch time over that of the fastest fixed tree (tolerance 0: a weight
    cut-off 4^-k or a depth cap) whose measured error is no worse (mean, and pixels off by more than 3/255)."""
    if not d.get("prices"):
        return
    print("\n| scene | default ms | price of the default | fixed tree that sets it | its ms | "
          "default mean / bad | fixed mean / bad | certified / estimated / unbounded (not estimated) pixels |")
    print("|---|---|---|---|---|---|---|---|")
    for p in d["prices"]:
        n = p["pixels"]
        fixed = p["fixed_setting"] or "–"
        if p["price_is_upper_bound"] and p["fixed_setting"]:
            fixed = f"none as accurate (slowest tried: {fixed})"
        fixed_error = ("–" if p["fixed_mean_abs_error"] is None
                       else f"{p['fixed_mean_abs_error']:.3f} / {p['fixed_bad_pixels']}")
        print(f"| {p['scene']} | {ms(p['default_ms'])} | {price(p)} | {fixed} | {ms(p['fixed_ms'])} | "
              f"{p['default_mean_abs_error']:.3f} / {p['default_bad_pixels']} | {fixed_error} | "
              f"{n['certified']} / {n['estimated']} / {n['unbounded_not_estimated']} of {n['total']} |")
    s = d.get("price_summary") or {}
    if s.get("geometric_mean") is not None:
        bounds = (f" ({s['upper_bounds']} of them upper bounds, so the mean is one too)"
                  if s["upper_bounds"] else "")
        worst = ("< " if s["worst_is_upper_bound"] else "") + f"{s['worst_price']:.3g}×"
        print(f"\nPrice of the default: geometric mean {'< ' if s['upper_bounds'] else ''}"
              f"{s['geometric_mean']:.3g}× over {s['scenes']} scenes{bounds}; worst {worst} on "
              f"{s['worst_scene']} ({s['worst_fixed_setting']}).")


def pareto(points):
    """The points no faster point is as accurate as, fastest first."""
    front, best = [], math.inf
    for p in sorted(points, key=lambda p: p[0]):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def plot(d, path, only=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogFormatterSciNotation, LogLocator, NullFormatter

    results = [r for r in d["results"] if not r["failure"]
               and (not only or any(r["scene"].startswith(prefix) for prefix in only))]
    scenes = []
    for r in results:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    floor = 1e-3  # an exact result still needs a place on a log axis
    prices_of = {p["scene"]: p for p in d.get("prices", [])}
    setters = {p["scene"]: p["fixed_setting"] for p in d.get("prices", []) if not p["price_is_upper_bound"]}
    columns = min(4, len(scenes))
    rows = math.ceil(len(scenes) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.4 * rows), squeeze=False)
    for ax in axes.flat[len(scenes):]:
        ax.set_visible(False)
    for ax, scene in zip(axes.flat, scenes):
        points = [(r["dispatch_ms"]["median"], max(r["error"]["mean_abs_error"], floor), r["setting"],
                   r.get("front", False)) for r in results if r["scene"] == scene]
        # The front: the fixed trees' (older files without them: every setting's).
        fixed = [p for p in points if p[3]]
        front = pareto(fixed or points)
        ax.plot([p[0] for p in front], [p[1] for p in front], color="tab:red", lw=1, zorder=1,
                label="front of the fixed trees")
        setter = setters.get(scene)
        for t, e, name, in_front in points:
            default = name == "default"
            if in_front:  # a fixed tree: named only where it sets the price
                ax.scatter([t], [e], s=10, zorder=2, color="tab:red", linewidths=0)
                if name == setter:
                    ax.annotate(name, (t, e), fontsize=6, xytext=(3, -7), textcoords="offset points",
                                color="tab:red")
                continue
            ax.scatter([t], [e], s=60 if default else 14, zorder=2,
                       facecolors="none" if default else "tab:blue", edgecolors="tab:blue",
                       linewidths=1.5 if default else 0.5)
            ax.annotate(name, (t, e), fontsize=6, xytext=(3, 2), textcoords="offset points")
        if scene in prices_of:
            ax.text(0.98, 0.97, f"price of the default {price(prices_of[scene])}", transform=ax.transAxes,
                    fontsize=7, ha="right", va="top")
        # What each setting guarantees: its stated bound (mean over pixels),
        # where no pixel's bound is infinite.
        stated = [(r["dispatch_ms"]["median"], max(r["stated_bound"]["mean"], floor))
                  for r in results if r["scene"] == scene and "stated_bound" in r
                  and not r["stated_bound"]["unbounded_pixels"]]
        if stated:
            ax.scatter([p[0] for p in stated], [p[1] for p in stated], s=14, marker="^", zorder=2,
                       facecolors="none", edgecolors="tab:green", linewidths=0.7, label="stated bound")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1, 2, 5)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_major_formatter(LogFormatterSciNotation())
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_title(scene, fontsize=9)
        ax.set_xlabel("dispatch time (ms)", fontsize=8)
        ax.set_ylabel("mean error, measured / stated (1/255)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="major", lw=0.3, alpha=0.5)
    fig.suptitle(f"snell bench: time against error, {d['size']}² — {d['device']}\n"
                 f"dots: measured against the limit; blue: the named settings, ringed: the default\n"
                 f"red: the fixed trees (cut-offs 4^-k, depth caps), their Pareto front, the one that prices the "
                 f"default named\ngreen triangles: the stated (guaranteed) bound; values below {floor} drawn at {floor}",
                 fontsize=11 if columns >= 4 else 8)
    fig.tight_layout(rect=(0, 0, 1, 0.92 if rows > 1 else 0.8))
    fig.savefig(path, dpi=90)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("json", help="bench.json written by snell bench")
    parser.add_argument("--plot", metavar="PNG", help="also draw time against error into this PNG")
    parser.add_argument("--only", metavar="PREFIX", action="append",
                        help="plot only the scenes whose name starts so (e.g. bench/); repeatable")
    args = parser.parse_args()
    d = json.load(open(args.json))
    tables(d)
    if args.plot:
        plot(d, args.plot, args.only)


if __name__ == "__main__":
    main()
