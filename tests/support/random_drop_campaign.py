#!/usr/bin/env python3
"""Runs random drops (generate_contact_scenes.py --random SEED, or --random-2d SEED with
--dimension 2) and flags the ones that break a rule of the contact stages: the total energy rising more
than 0.1 % above its value after the first step, collision impulses or the second contact step
adding kinetic energy (1e-12 relative), a deepest overlap over 5 % of the smaller body's size,
a non-zero exit, a NaN; with --compare-threads N also a final state (summary.json's state_hash)
that differs on N threads.

    /usr/bin/python3 tests/support/random_drop_campaign.py FIRST LAST [--monolith build/monolith]
        [--threads 2] [--work /tmp/random_drops] [--dimension 2] [--compare-threads 1]
        [--set solvers.contact.KEY=VALUE ...]

One line per seed: its wall time and OK, or what it broke. Plain Python, no modules needed.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scenarios", "scenes"))
import generate_contact_scenes  # noqa: E402


def state_hash(out):
    try:
        with open(os.path.join(out, "summary.json")) as f:
            return json.load(f).get("state_hash")
    except (OSError, ValueError):
        return None


def check(seed, monolith, threads, work, dimension=3, compare_threads=0, overrides=()):
    if dimension == 2:
        generate_contact_scenes.random_drop_2d(work, seed)
        scene = os.path.join(work, "random_drop_2d_%d.json" % seed)
    else:
        generate_contact_scenes.random_drop(work, seed)
        scene = os.path.join(work, "random_drop_%d.json" % seed)
    out = os.path.join(work, "out_%d" % seed)
    start = time.time()
    try:
        settings = [arg for pair in overrides for arg in ("--set", pair)]
        run = subprocess.run([monolith, "run", scene, "--threads", str(threads), "--no-frames", "--out", out, "--quiet"]
                             + settings,
                             capture_output=True, text=True, timeout=600)
    except subprocess.TimeoutExpired:
        return ["no result in 600 s"], time.time() - start
    seconds = time.time() - start
    flags = []
    if run.returncode != 0:
        flags.append("exit %d: %s" % (run.returncode, (run.stderr or run.stdout).strip()[-300:]))
    try:
        with open(os.path.join(out, "metrics.csv")) as f:
            rows = list(csv.DictReader(f))
    except OSError:
        return flags + ["no metrics.csv"], seconds
    if not rows:
        return flags + ["no steps"], seconds
    if any(not math.isfinite(float(v)) for row in rows for k, v in row.items() if k != "step"):
        flags.append("NaN or inf in metrics.csv")
        return flags, seconds
    first = float(rows[0]["total_energy"])
    rise = max(float(r["total_energy"]) for r in rows) - first
    if rise > 1e-3 * abs(first):
        flags.append("total energy rose %.3g %%" % (100 * rise / abs(first)))
    for name in ("collision_energy_change", "velocity_contact_energy_change"):
        gain = max(float(r[name]) for r in rows)
        if gain > 1e-12:
            flags.append("%s %.3g" % (name, gain))
    overlap = max(float(r["max_penetration_ratio"]) for r in rows)
    if overlap > 0.05:
        flags.append("deepest overlap %.1f %%" % (100 * overlap))
    if compare_threads and compare_threads != threads:
        # The same scene on another thread count must end in bitwise the same state.
        other = out + "_threads_%d" % compare_threads
        subprocess.run([monolith, "run", scene, "--threads", str(compare_threads), "--no-frames", "--out", other,
                        "--quiet"] + [arg for pair in overrides for arg in ("--set", pair)],
                       capture_output=True, text=True, timeout=600)
        mine, theirs = state_hash(out), state_hash(other)
        if mine is None or mine != theirs:
            flags.append("state on %d threads %s, on %d threads %s" % (threads, mine, compare_threads, theirs))
    return flags, seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("first", type=int)
    parser.add_argument("last", type=int)
    parser.add_argument("--monolith", default=os.path.join(HERE, "..", "..", "build", "monolith"))
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--work", default="/tmp/random_drops")
    parser.add_argument("--dimension", type=int, choices=(2, 3), default=3,
                        help="2: the 2-D drops of generate_contact_scenes.py --random-2d")
    parser.add_argument("--compare-threads", type=int, default=0, metavar="N",
                        help="also run each seed on N threads and flag a final state that differs")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a scene override for every run (monolith run --set), repeatable")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    broken = 0
    for seed in range(args.first, args.last + 1):
        flags, seconds = check(seed, args.monolith, args.threads, args.work, args.dimension, args.compare_threads,
                               args.set)
        broken += 1 if flags else 0
        print("%d %.1fs %s" % (seed, seconds, "OK" if not flags else " | ".join(flags)), flush=True)
    print("%d of %d seeds flagged" % (broken, args.last - args.first + 1))


if __name__ == "__main__":
    main()
