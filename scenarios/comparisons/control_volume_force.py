#!/usr/bin/env python3
"""An independent check of the DFG disk's force estimate (`obstacle_forces`): the momentum
balance of the box [0.1, 0.35] x [0.1, 0.3] around the disk, from probes sampled every step.

  F_body = -d/dt (sum of rho u over the box) - (momentum flux + pressure over the box's sides),

with the box's momentum by the midpoint rule on the 220 x 41 grid's cell centres (cells whose
centre lies in the disk left out), its sides sampled at the cells' edge midpoints, and the time
derivative by central differences. The viscous stress on the box's sides is left out (it is
small there at Re 100, about 2 % of the drag). Coefficients c = 20 F (rho = 1, Ubar = 1, D = 0.1).

Usage (from the repository root, after building):
  /usr/bin/python3 scenarios/comparisons/control_volume_force.py [--out DIR] [--end 7.2] [--from 6]
Runs ./build/monolith on scenarios/scenes/dfg_2d2.json (its 220 x 41 grid, dt 0.004) with the
probes, then prints the maxima of c_D and c_L over t >= --from by both estimates.
"""
import argparse
import csv
import json
import math
import subprocess

H = 0.01  # the scene's cell size
BOX_X, BOX_Y = (0.1, 0.35), (0.1, 0.3)
CENTRE, RADIUS = (0.2, 0.2), 0.05
XS = [BOX_X[0] + H * (i + 0.5) for i in range(round((BOX_X[1] - BOX_X[0]) / H))]
YS = [BOX_Y[0] + H * (j + 0.5) for j in range(round((BOX_Y[1] - BOX_Y[0]) / H))]
SIDES = [("b", 0, -1), ("t", 0, 1), ("l", -1, 0), ("r", 1, 0)]  # name, outward normal


def side_points(name):
    if name in ("b", "t"):
        y = BOX_Y[0] if name == "b" else BOX_Y[1]
        return [(x, y) for x in XS]
    x = BOX_X[0] if name == "l" else BOX_X[1]
    return [(x, y) for y in YS]


def probes():
    points = [{"name": f"c_{i}_{j}", "position": [round(x, 6), round(y, 6)]} for i, x in enumerate(XS) for j, y in enumerate(YS)]
    for name, _, _ in SIDES:
        points += [{"name": f"{name}_{k}", "position": [round(x, 6), round(y, 6)]} for k, (x, y) in enumerate(side_points(name))]
    return points


def box_momentum(row):
    px = py = 0.0
    for i, x in enumerate(XS):
        for j, y in enumerate(YS):
            if math.hypot(x - CENTRE[0], y - CENTRE[1]) < RADIUS:
                continue
            px += float(row[f"c_{i}_{j}_u"]) * H * H
            py += float(row[f"c_{i}_{j}_v"]) * H * H
    return px, py


def side_terms(row):
    """Momentum flux plus pressure force through the box's sides, (x, y)."""
    fx = fy = 0.0
    for name, nx, ny in SIDES:
        for k in range(len(side_points(name))):
            u, v, p = (float(row[f"{name}_{k}_{c}"]) for c in ("u", "v", "p"))
            un = u * nx + v * ny
            fx += (u * un + p * nx) * H
            fy += (v * un + p * ny) * H
    return fx, fy


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="/tmp/monolith_control_volume")
    parser.add_argument("--end", type=float, default=7.2)
    parser.add_argument("--from", dest="start", type=float, default=6.0)
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    subprocess.run(["./build/monolith", "run", "scenarios/scenes/dfg_2d2.json", "--out", args.out, "--no-frames", "--quiet",
                    "--threads", str(args.threads), "--set", f"time.end={args.end}",
                    "--set", "output.probes=" + json.dumps(probes(), separators=(",", ":"))], check=True)
    rows = list(csv.DictReader(open(f"{args.out}/probes.csv")))
    metrics = list(csv.DictReader(open(f"{args.out}/metrics.csv")))
    momentum = [box_momentum(r) for r in rows]
    times = [float(r["time"]) for r in rows]
    control, solver = [], []
    for k in range(1, len(rows) - 1):
        if times[k] < args.start:
            continue
        span = times[k + 1] - times[k - 1]
        sx, sy = side_terms(rows[k])
        control.append((20 * (-(momentum[k + 1][0] - momentum[k - 1][0]) / span - sx),
                        20 * (-(momentum[k + 1][1] - momentum[k - 1][1]) / span - sy)))
        solver.append((20 * float(metrics[k]["obstacle_cylinder_force_x"]), 20 * float(metrics[k]["obstacle_cylinder_force_y"])))
    for label, series in (("control volume", control), ("obstacle_forces", solver)):
        print(f"{label:>16}: c_D,max {max(c[0] for c in series):.4f}  c_L,max {max(c[1] for c in series):.4f}  "
              f"c_L,min {min(c[1] for c in series):.4f}")


if __name__ == "__main__":
    main()
