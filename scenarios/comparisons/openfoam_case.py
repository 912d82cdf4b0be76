"""What the OpenFOAM comparison drivers share: writing a case's dictionaries, finding Debian's
OpenFOAM, and running (and timing) its utilities and solvers."""
import os
import shutil
import subprocess
import sys
import time

HEADER = "FoamFile {{ version 2.0; format ascii; class {cls}; object {obj}; }}\n"


def require_openfoam(script):
    """Exits with a clear message when OpenFOAM is missing; points Debian's build at its etc/."""
    if shutil.which("blockMesh") is None:
        sys.exit(f"{script}: OpenFOAM is not installed (Debian 12: apt-get install openfoam)")
    # Debian's package finds its etc/ (the global controlDict) through WM_PROJECT_DIR.
    os.environ.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def run(case, args, log):
    """Runs one OpenFOAM command in the case, its output to the case's file `log`."""
    with open(os.path.join(case, log), "w") as out:
        subprocess.run(args, cwd=case, stdout=out, stderr=subprocess.STDOUT, check=True)


def solve(case, app, procs):
    """Runs the solver, decomposed over `procs` MPI ranks if > 1 (then reconstructs the last
    time); returns the solver's wall seconds alone."""
    if procs > 1:
        run(case, ["decomposePar", "-force"], "log.decomposePar")
        command = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(procs), app, "-parallel"]
    else:
        command = [app]
    start = time.perf_counter()
    run(case, command, "log." + app)
    seconds = time.perf_counter() - start
    if procs > 1:
        run(case, ["reconstructPar", "-latestTime"], "log.reconstructPar")
    return seconds
