#!/usr/bin/env python3
"""Draws the single-vortex test of the particle level set from `bench_surface_tension vortex T N fronts=PREFIX`.

usage: plot_vortex.py OUT.png PREFIX_N.csv [TITLE]
Each CSV row: scheme (plain|particles), time label (0|half|end), x0, y0, x1, y1 (one front segment).
Two panels, the plain level set and the particle level set, each with the circle at t = 0, the
stretched interface at T/2 and the returned interface at T.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import LineCollection

STYLES = {"0": ("black", "t = 0"), "half": ("tab:blue", "t = T/2"), "end": ("tab:red", "t = T")}
TITLES = {"plain": "level set (semi-Lagrangian + fast marching)", "particles": "particle level set"}


def main():
    out, name = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else ""
    segments = {}
    with open(name) as f:
        for row in csv.reader(f):
            scheme, label = row[0], row[1]
            x0, y0, x1, y1 = map(float, row[2:6])
            segments.setdefault((scheme, label), []).append([(x0, y0), (x1, y1)])
    fig, axes = plt.subplots(1, 2, figsize=(10, 5.2))
    for ax, scheme in zip(axes, ["plain", "particles"]):
        for label, (colour, text) in STYLES.items():
            lines = segments.get((scheme, label), [])
            ax.add_collection(LineCollection(lines, colors=colour, linewidths=1.2, label=text))
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.set_aspect("equal")
        ax.set_title(TITLES[scheme], fontsize=10)
        ax.legend(loc="lower right", fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
