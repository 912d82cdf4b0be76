#!/usr/bin/python3
"""PNG plots of a Monolith run directory or sweep table (`monolith plot`, docs/tools.md).

A run directory (metrics.csv): energies, momenta, solver iterations and per-stage wall time
against time, one panel each, into RUN/plots.png (or --out).
A sweep.csv: --y columns against --x (default: every check error against us_per_step, the
speed-against-error front), log axes with --logx/--logy; points sharing the other varied values
are joined by lines. Uses Debian's python3-matplotlib (Agg backend, no display needed).
A run directory with --frame [TIME]: one frame of its ParaView output drawn by render_frame.py.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    try:
        if "/" in text:
            a, b = text.split("/")
            return float(a) / float(b)
        return float(text)
    except (ValueError, ZeroDivisionError):
        return math.nan


def plot_run(directory, out):
    rows = read_csv(os.path.join(directory, "metrics.csv"))
    if not rows:
        sys.exit("monolith plot: %s/metrics.csv has no rows" % directory)
    cols = list(rows[0].keys())
    t = [number(r["time"]) for r in rows]
    panels = [
        ("energy (J)", [c for c in ("kinetic_energy", "potential_energy", "total_energy") if c in cols], False),
        ("momentum", [c for c in cols if c.startswith("linear_momentum_") or c.startswith("angular_momentum_")], False),
        ("solver iterations", [c for c in cols if "iterations" in c], False),
        ("wall time per stage (s)", [c for c in cols if c.startswith("stage_") and c.endswith("_seconds")], True),
    ]
    panels = [p for p in panels if p[1]]
    fig, axes = plt.subplots(len(panels), 1, figsize=(9, 3 * len(panels)), sharex=True, squeeze=False)
    for ax, (title, names, log) in zip(axes[:, 0], panels):
        for n in names:
            ax.plot(t, [number(r[n]) for r in rows], label=n, linewidth=1)
        ax.set_ylabel(title)
        if log:
            ax.set_yscale("log")
        ax.legend(fontsize=7, loc="best")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time (s)")
    fig.suptitle(os.path.basename(os.path.normpath(directory)))
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def plot_sweep(path, xcol, ycols, logx, logy, out):
    rows = [r for r in read_csv(path) if r.get("exit_code") in ("0", "5")]
    if not rows:
        sys.exit("monolith plot: %s has no completed rows" % path)
    cols = list(rows[0].keys())
    if not ycols:
        ycols = [c for c in cols if c.startswith("check_") and c.endswith("_error")]
    for c in [xcol] + ycols:
        if c not in cols:
            sys.exit("monolith plot: no column '%s' in %s (columns: %s)" % (c, path, ", ".join(cols)))
    fixed = ["point", "repeat", "exit_code", "status", "steps", "wall_seconds", "us_per_step", "state_hash"]
    varied = cols[1:cols.index("repeat")]
    series_keys = [v for v in varied if v != xcol]
    # Against a measured column (the cost), the first varied column runs along each line and the
    # others tell the lines apart: e.g. one line per order, its points the time steps.
    along = series_keys.pop(0) if xcol not in varied and series_keys else None
    fig, axes = plt.subplots(len(ycols), 1, figsize=(8, 4.5 * len(ycols)), squeeze=False)
    for ax, y in zip(axes[:, 0], ycols):
        groups = {}
        for r in rows:
            key = ", ".join("%s=%s" % (k, r[k]) for k in series_keys if k != y)
            groups.setdefault(key, []).append((number(r[xcol]), number(r[y]), r[along] if along else ""))
        for key, pts in groups.items():
            pts = sorted(p for p in pts if not (math.isnan(p[0]) or math.isnan(p[1])))
            if logx:
                pts = [p for p in pts if p[0] > 0]
            if logy:
                pts = [p for p in pts if p[1] > 0]
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=key or y, markersize=4)
                for p in pts:
                    if p[2]:
                        ax.annotate(p[2], (p[0], p[1]), fontsize=6, xytext=(3, 3), textcoords="offset points")
        ax.set_xlabel(xcol)
        ax.set_ylabel(y)
        if logx:
            ax.set_xscale("log")
        if logy:
            ax.set_yscale("log")
        ax.grid(alpha=0.3, which="both")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="best", title=along)
    del fixed
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def main():
    p = argparse.ArgumentParser(prog="monolith plot")
    p.add_argument("source", help="a run directory or a sweep.csv")
    p.add_argument("--x", default="us_per_step")
    p.add_argument("--y", action="append", default=[])
    p.add_argument("--logx", action="store_true")
    p.add_argument("--logy", action="store_true")
    p.add_argument("--frame", nargs="?", const="last", metavar="TIME",
                   help="render the run's frame nearest TIME (default: the last) instead of plotting metrics")
    p.add_argument("--field", default="speed", help="with --frame: the fluid field drawn")
    p.add_argument("--view", default="-35,25", help="with --frame: 3-D camera azimuth,elevation (--view=-35,25)")
    p.add_argument("--out")
    a = p.parse_args()
    if a.frame is not None:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import render_frame

        time = None
        if a.frame != "last":
            try:
                time = float(a.frame)
            except ValueError:
                sys.exit("monolith plot: --frame expects a time or nothing, got '%s'" % a.frame)
        render_frame.main([a.source, "--field", a.field, "--view=" + a.view] +
                          (["--time", str(time)] if time is not None else []) + (["--out", a.out] if a.out else []))
        return
    if os.path.isdir(a.source):
        out = a.out or os.path.join(a.source, "plots.png")
        plot_run(a.source, out)
    elif a.source.endswith(".csv"):
        out = a.out or os.path.splitext(a.source)[0] + ".png"
        plot_sweep(a.source, a.x, a.y, a.logx, a.logy, out)
    else:
        sys.exit("monolith plot: %s is neither a run directory nor a .csv" % a.source)
    print(out)


if __name__ == "__main__":
    main()
