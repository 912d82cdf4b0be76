#!/usr/bin/env python3
"""Draws Figs. 6.6/6.7-style stability maps from `bench_surface_tension stability_csv` rows.

usage: plot_stability_map.py OUT.png CSV...
Each CSV row: shape, scheme, N, dt multiple, dt, stable (1/0), steps, max speed, wall s.
One panel per shape; x: 1/dx (N cells across 0.04 m), y: dt as a multiple of the explicit
capillary limit sqrt(rho dx^3 / (4 pi sigma)); each scheme a column of marks beside the others:
o stable for all steps, x unstable.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

SCHEMES = ["ft_explicit", "ft_implicit", "ls_explicit", "ls_implicit", "pressure_jump"]
LABELS = {"ft_explicit": "front tracking, explicit", "ft_implicit": "front tracking, implicit",
          "ls_explicit": "level set, explicit", "ls_implicit": "level set, implicit",
          "ls_implicit_update": "level set, implicit update", "pressure_jump": "pressure jump"}
COLOURS = {"ft_explicit": "tab:orange", "ft_implicit": "tab:red", "ls_explicit": "tab:cyan",
           "ls_implicit": "tab:blue", "ls_implicit_update": "tab:purple", "pressure_jump": "tab:gray"}


def main():
    out, files = sys.argv[1], sys.argv[2:]
    rows = []
    for name in files:
        with open(name) as f:
            rows += [r for r in csv.reader(f) if len(r) >= 6 and r[0] in ("circle", "ellipse")]
    shapes = [s for s in ("circle", "ellipse") if any(r[0] == s for r in rows)]
    schemes = []
    for r in rows:
        if r[1] not in schemes:
            schemes.append(r[1])
    schemes.sort(key=lambda s: list(LABELS).index(s) if s in LABELS else 99)
    fig, axes = plt.subplots(1, len(shapes), figsize=(6.5 * len(shapes), 6.5), squeeze=False)
    for ax, shape in zip(axes[0], shapes):
        ns = sorted({int(r[2]) for r in rows if r[0] == shape})
        width = 0.8 / max(1, len(schemes))
        for k, scheme in enumerate(schemes):
            offset = (k - (len(schemes) - 1) / 2) * width
            for r in rows:
                if r[0] != shape or r[1] != scheme:
                    continue
                x = ns.index(int(r[2])) + offset
                y = float(r[3])
                stable = r[5] == "1"
                colour = COLOURS.get(scheme, "k")
                if stable:
                    ax.scatter([x], [y], marker="o", s=40, facecolors="none", edgecolors=colour, linewidths=1.5)
                else:
                    ax.scatter([x], [y], marker="x", s=50, c=colour, linewidths=1.5)
            ax.scatter([], [], marker="s", color=COLOURS.get(scheme, "k"), label=LABELS.get(scheme, scheme))
        ax.set_yscale("log", base=2)
        ax.invert_yaxis()  # smaller dt at the top, as in the thesis's figures
        ax.set_xticks(range(len(ns)))
        ax.set_xlim(-0.5, len(ns) - 0.5)
        ax.set_xticklabels([f"N = {n}\n(dx = {0.04 / n * 1e3:.2f} mm)" for n in ns])
        ax.set_ylabel("dt / explicit capillary limit sqrt(rho dx^3 / (4 pi sigma))")
        ax.set_title(f"{shape}: o stable for 500 steps, x unstable")
        ax.grid(True, axis="y", alpha=0.3)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3, fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
