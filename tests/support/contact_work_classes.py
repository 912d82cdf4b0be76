#!/usr/bin/env python3
"""Splits a 1-thread callgrind profile of a rigid-contact run into what two threads can share
and what stays on one, and bounds the 2-thread speed-up from it (instruction counts: exact,
whatever the machine's load).

    valgrind --tool=callgrind --callgrind-out-file=ONE build/monolith run SCENE --threads 1 ...
    valgrind --tool=callgrind --callgrind-out-file=TWO build/monolith run SCENE --threads 2 ...
    /usr/bin/python3 tests/support/contact_work_classes.py ONE [--two TWO...] [--dag-factor 1.93]

Classes of the step (Simulation::step, inclusive):
  ordered   the ordered tasks' bodies (ContactWorkspace::runTask, push-out's central-body task):
            shared as far as their dependencies allow; --dag-factor is the work over the
            2-thread list schedule of their block graphs (measured separately, see
            docs/benchmarks_rigid_contact.md);
  loops     the plain parallel loops (one slot per body or pair) and the broad phase's tree
            pass (run as jobs on two threads): halved;
  serial    the rest: the jam solve, the pair-list, island and level rebuilds, the recording
            of the ordered tasks, the tree's refit, push-out's bookkeeping between rounds.
With --two, the extra instructions of the 2-thread run (recording the dependencies, handing
tasks over) count as serial too. A 2-thread callgrind run's per-thread split is no measure:
valgrind runs one thread at a time, so the main thread takes most chunks of a plain loop.
"""
import argparse
import re
import subprocess
import sys

LOOP_BODIES = ["pack(", "measurePairs", "computeLevels()", "AdvanceRigidPositions", "growPairs", "rebuildPairsFrom",
               "updateAllCandidates", "RigidHalfKick", "GravityForce", "ClearRigidForces", "sortIslandPairsByLevel",
               "clampStepEnergyGain", "BroadPhase<3>::Impl::runJobs", "BroadPhase<2>::Impl::runJobs"]


def inclusive(path):
    out = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", path],
                         capture_output=True, text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+) \(\s*[\d.]+%\)\s+(.*)$", line)
        if m:
            rows.append((int(m.group(1).replace(",", "")), m.group(2)))
    return rows


def program_total(path):
    out = subprocess.run(["callgrind_annotate", path], capture_output=True, text=True, check=True).stdout
    m = re.search(r"([\d,]+) \(100\.0%\)\s+PROGRAM TOTALS", out)
    return int(m.group(1).replace(",", ""))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("one", help="callgrind output of the 1-thread run")
    p.add_argument("--two", nargs="+", help="callgrind output of the 2-thread run (with --separate-threads: "
                                           "every thread's file)")
    p.add_argument("--dag-factor", type=float, default=2.0,
                   help="ordered-task work over its 2-thread schedule (at most 2)")
    a = p.parse_args()
    rows = inclusive(a.one)

    def pick(pred):
        return sum(v for v, n in rows if pred(n))

    step = max(v for v, n in rows if "Simulation<" in n and ">::step" in n)
    ordered = pick(lambda n: "ContactWorkspace<" in n and ">::runTask(" in n) + \
        pick(lambda n: n.startswith("???:std::_Function_handler<void (int), monolith::solvers::contact::PushOutRounds<")
             and "pushApart" in n)
    loops = pick(lambda n: "start_for<" in n and "::execute(" in n and any(b in n for b in LOOP_BODIES))
    loops += pick(lambda n: n.startswith("???:fcl::DynamicAABBTreeCollisionManager<double>::collide("))
    serial = step - ordered - loops
    extra = sum(program_total(f) for f in a.two) - program_total(a.one) if a.two else 0
    two = serial + extra + ordered / a.dag_factor + loops / 2
    g = 1e9
    print(f"step {step / g:.3f} G: ordered tasks {ordered / g:.3f} G, parallel loops {loops / g:.3f} G, "
          f"serial {serial / g:.3f} G ({100 * serial / step:.1f} %)")
    if a.two:
        print(f"2-thread run: {extra / g:.3f} G more instructions (recording, handing over)")
    print(f"bound on 2 threads: {two / g:.3f} G, speed-up at most {step / two:.3f}x "
          f"(dag factor {a.dag_factor})")


if __name__ == "__main__":
    sys.exit(main())
