#!/usr/bin/env python3
"""Write a scaling scene: N spheres in a jittered grid filling a fixed box in
front of the SPEC camera, a floor and two lights. Used to measure render time
against sphere count: python3 bench/make_scaling_scene.py N > out.scn"""
import math
import random
import sys


def main() -> None:
    if len(sys.argv) != 2 or not sys.argv[1].isdigit() or int(sys.argv[1]) < 1:
        sys.exit("usage: make_scaling_scene.py N   (N >= 1 spheres)")
    n = int(sys.argv[1])
    rng = random.Random(n)
    side = max(1, round(n ** (1 / 3)))
    cell = 2.0 / side
    radius = 0.35 * cell
    out = [f"# scaling scene: {n} spheres in a {side}^3 jittered grid", "view 512 0.5",
           "background 0.05 0.05 0.1", "ambient 0.1 0.1 0.1",
           "light 1 1 1 2 4 3", "light 0.4 0.4 0.5 -3 1 2",
           "group", "material 0.6 0.6 0.6 0 0 0 1", "move 0 -101.2 -4", "scale 100 100 100", "sphere", "groupend"]
    for k in range(n):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        x = -1 + (i + 0.5) * cell + rng.uniform(-0.1, 0.1) * cell
        y = -1 + (j + 0.5) * cell + rng.uniform(-0.1, 0.1) * cell
        z = -3 - (l + 0.5) * cell
        mirror = k % 5 == 0
        out.append("material 0.1 0.1 0.1 0.6 0.6 0.6 50" if mirror else
                   f"material {rng.uniform(0.2, 0.9):.3f} {rng.uniform(0.2, 0.9):.3f} {rng.uniform(0.2, 0.9):.3f} 0.2 0.2 0.2 20")
        out += ["group", f"move {x:.6f} {y:.6f} {z:.6f}", f"scale {radius:.6f} {radius:.6f} {radius:.6f}", "sphere", "groupend"]
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
