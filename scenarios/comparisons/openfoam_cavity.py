#!/usr/bin/env python3
"""Lid-driven cavity in OpenFOAM on the grid `bench_cavity` uses: the finite-volume comparison of
the fluid requirements ("report wall time to reach steady state; we will hold it against a widely used
finite-volume code on the same grid").

Writes an OpenFOAM case (unit square, lid speed 1, nu = 1/Re, N x N x 1 cells, the same step
dt = 1/N as scenarios/scenes/cavity_re100.json), runs it, times the solver and prints, in
bench_cavity's units, the largest deviation of the centre-line velocities from Ghia, Ghia & Shin
(1982) and the steady-state measure max|u(t) - u(t - dt)| / dt of the last step.

Solvers:
  ico     transient PISO (icoFoam), run to the simulated time Monolith needed to reach
          max|du|/dt < 1e-6 (pass it with --end), then one more step to measure max|du|/dt;
  simple  steady SIMPLEC (simpleFoam, laminar), stopped when the initial residuals of U and p
          fall below 1e-6 (OpenFOAM's own convergence control; no time accuracy involved).

Needs OpenFOAM (Debian 12: `apt-get install openfoam`, version v1912). Not part of CI.
Usage: /usr/bin/python3 scenarios/comparisons/openfoam_cavity.py --re 100 --cells 128 \
           --solver ico --end 21.16 [--procs 2] [--keep DIR]
"""
import argparse
import os
import re
import shutil
import sys
import tempfile

from openfoam_case import HEADER, require_openfoam, run, solve, write

# Ghia, Ghia & Shin (1982) centre-line values, as in tests/support/ghia.h (coordinate, Re 100, Re 1000).
GHIA_U = [(1.0000, 1.00000, 1.00000), (0.9766, 0.84123, 0.65928), (0.9688, 0.78871, 0.57492),
          (0.9609, 0.73722, 0.51117), (0.9531, 0.68717, 0.46604), (0.8516, 0.23151, 0.33304),
          (0.7344, 0.00332, 0.18719), (0.6172, -0.13641, 0.05702), (0.5000, -0.20581, -0.06080),
          (0.4531, -0.21090, -0.10648), (0.2813, -0.15662, -0.27805), (0.1719, -0.10150, -0.38289),
          (0.1016, -0.06434, -0.29730), (0.0703, -0.04775, -0.22220), (0.0625, -0.04192, -0.20196),
          (0.0547, -0.03717, -0.18109), (0.0000, 0.00000, 0.00000)]
GHIA_V = [(1.0000, 0.00000, 0.00000), (0.9688, -0.05906, -0.21388), (0.9609, -0.07391, -0.27669),
          (0.9531, -0.08864, -0.33714), (0.9453, -0.10313, -0.39188), (0.9063, -0.16914, -0.51550),
          (0.8594, -0.22445, -0.42665), (0.8047, -0.24533, -0.31966), (0.5000, 0.05454, 0.02526),
          (0.2344, 0.17527, 0.32235), (0.2266, 0.17507, 0.33075), (0.1563, 0.16077, 0.37095),
          (0.0938, 0.12317, 0.32627), (0.0781, 0.10890, 0.30353), (0.0703, 0.10091, 0.29012),
          (0.0625, 0.09233, 0.27485), (0.0000, 0.00000, 0.00000)]


def write_case(case, n, nu, solver, dt, steps, procs, loose, gamg, write_every=None):
    """The case's dictionaries; results are written every `write_every` steps (default: at the end)."""
    write_every = write_every or steps
    write(f"{case}/system/blockMeshDict", HEADER.format(cls="dictionary", obj="blockMeshDict") + f"""
scale 1;
vertices ((0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 0.01) (1 0 0.01) (1 1 0.01) (0 1 0.01));
blocks (hex (0 1 2 3 4 5 6 7) ({n} {n} 1) simpleGrading (1 1 1));
boundary
(
    lid {{ type wall; faces ((3 7 6 2)); }}
    walls {{ type wall; faces ((0 4 7 3) (2 6 5 1) (1 5 4 0)); }}
    frontAndBack {{ type empty; faces ((0 3 2 1) (4 5 6 7)); }}
);
""")
    if solver == "ico":
        control = f"application icoFoam; deltaT {dt!r}; endTime {steps * dt!r}; writeInterval {write_every};"
        schemes = "ddtSchemes { default Euler; } divSchemes { default none; div(phi,U) Gauss linear; }"
        solution = """
solvers
{
    p { %(p_solver)s; tolerance %(tol_p)s; relTol %(rel_p)s; }
    pFinal { $p; relTol 0; }
    U { solver smoothSolver; smoother symGaussSeidel; tolerance %(tol_u)s; relTol 0; }
}
PISO { nCorrectors 2; nNonOrthogonalCorrectors 0; pRefCell 0; pRefValue 0; }
""" % dict({"tol_p": "1e-6", "rel_p": "0.05", "tol_u": "1e-5"} if loose else {"tol_p": "1e-10", "rel_p": "0.01", "tol_u": "1e-10"},
           p_solver="solver GAMG; smoother GaussSeidel" if gamg else "solver PCG; preconditioner DIC")
        transport = "nu [0 2 -1 0 0 0 0] %r;\n" % nu
    else:
        control = f"application simpleFoam; deltaT 1; endTime {steps}; writeInterval {write_every};"
        schemes = ("ddtSchemes { default steadyState; } divSchemes { default none; "
                   "div(phi,U) bounded Gauss linear; div((nuEff*dev2(T(grad(U))))) Gauss linear; }")
        solution = """
solvers
{
    p { solver GAMG; smoother GaussSeidel; tolerance 1e-10; relTol 0.05; }
    U { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-10; relTol 0.1; }
}
SIMPLE
{
    nNonOrthogonalCorrectors 0; consistent yes; pRefCell 0; pRefValue 0;
    residualControl { p 1e-6; U 1e-6; }
}
relaxationFactors { equations { U 0.9; } }
"""
        transport = "transportModel Newtonian;\nnu %r;\n" % nu
        write(f"{case}/constant/turbulenceProperties",
              HEADER.format(cls="dictionary", obj="turbulenceProperties") + "simulationType laminar;\n")
    write(f"{case}/system/controlDict", HEADER.format(cls="dictionary", obj="controlDict") + f"""
{control}
startFrom latestTime; startTime 0; stopAt endTime;
writeControl timeStep; purgeWrite 0; writeFormat ascii; writePrecision 12;
writeCompression off; timeFormat general; timePrecision 12; runTimeModifiable false;
""")
    write(f"{case}/system/fvSchemes", HEADER.format(cls="dictionary", obj="fvSchemes") + schemes + """
gradSchemes { default Gauss linear; }
laplacianSchemes { default Gauss linear orthogonal; }
interpolationSchemes { default linear; }
snGradSchemes { default orthogonal; }
""")
    write(f"{case}/system/fvSolution", HEADER.format(cls="dictionary", obj="fvSolution") + solution)
    write(f"{case}/system/decomposeParDict", HEADER.format(cls="dictionary", obj="decomposeParDict") +
          f"numberOfSubdomains {procs};\nmethod simple;\n"
          f"coeffs {{ n (1 {procs} 1); }}\n")  # horizontal strips (Debian's build has no scotch)
    write(f"{case}/constant/transportProperties", HEADER.format(cls="dictionary", obj="transportProperties") + transport)
    write(f"{case}/0/U", HEADER.format(cls="volVectorField", obj="U") + """
dimensions [0 1 -1 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{
    lid { type fixedValue; value uniform (1 0 0); }
    walls { type noSlip; }
    frontAndBack { type empty; }
}
""")
    write(f"{case}/0/p", HEADER.format(cls="volScalarField", obj="p") + """
dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    lid { type zeroGradient; }
    walls { type zeroGradient; }
    frontAndBack { type empty; }
}
""")


def latest_time(case):
    times = [d for d in os.listdir(case) if re.fullmatch(r"[0-9.e+-]+", d) and d != "0"]
    return max(times, key=float)


def read_velocity(case, time_dir, n):
    """Cell-centred velocities, blockMesh order (x fastest): list of (u, v) rows by j."""
    with open(os.path.join(case, time_dir, "U")) as f:
        text = f.read()
    body = text.split("internalField", 1)[1]
    count = int(re.search(r"List<vector>\s*(\d+)", body).group(1))
    if count != n * n:
        raise RuntimeError(f"{case}/{time_dir}/U: expected {n * n} cells, found {count}")
    values = re.findall(r"\(([-0-9.eE+]+) ([-0-9.eE+]+) [-0-9.eE+]+\)", body)[:count]
    return [[(float(values[j * n + i][0]), float(values[j * n + i][1])) for i in range(n)] for j in range(n)]


def sample(field, n, component, x, y):
    """Bilinear between cell centres along x; along y, between centres and, within half a cell of
    the bottom wall or the lid, linear to the wall's value (0, or the lid's u = 1)."""
    def row(j):  # the x-interpolated value on cell-centre row j
        t = x * n - 0.5
        i = int(t // 1)
        w = t - i
        if i < 0 or i >= n - 1:
            raise RuntimeError("sampling next to a side wall is not needed for the centre lines")
        return (1 - w) * field[j][i][component] + w * field[j][i + 1][component]

    lid = 1.0 if component == 0 else 0.0
    t = y * n - 0.5
    if t < 0:  # below the first centre: to the bottom wall's 0
        return row(0) * (y * n / 0.5)
    if t >= n - 1:  # above the last centre: to the lid
        w = (y * n - (n - 0.5)) / 0.5
        return (1 - w) * row(n - 1) + w * lid
    j = int(t // 1)
    w = t - j
    return (1 - w) * row(j) + w * row(j + 1)


def ghia_deviation(field, n, reynolds):
    column = 1 if reynolds == 100 else 2
    worst_u = max(abs(sample(field, n, 0, 0.5, p[0]) - p[column]) for p in GHIA_U if 0 < p[0] < 1)
    worst_v = max(abs(sample(field, n, 1, p[0], 0.5) - p[column]) for p in GHIA_V if 0 < p[0] < 1)
    return worst_u, worst_v


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--re", type=int, choices=(100, 1000), default=100)
    parser.add_argument("--cells", type=int, default=128)
    parser.add_argument("--solver", choices=("ico", "simple"), default="ico")
    parser.add_argument("--end", type=float, help="simulated time for icoFoam (Monolith's time to steady state)")
    parser.add_argument("--dt", type=float, help="icoFoam step (default 1/cells, as the scene)")
    parser.add_argument("--iterations", type=int, default=20000, help="simpleFoam iteration cap")
    parser.add_argument("--procs", type=int, default=1)
    parser.add_argument("--loose", action="store_true",
                        help="icoFoam with the cavity tutorial's tolerances (p 1e-6, relTol 0.05; U 1e-5) "
                             "instead of 1e-10 (Monolith's scene solves to a relative 1e-10)")
    parser.add_argument("--gamg", action="store_true",
                        help="icoFoam's pressure with GAMG instead of the tutorial's DIC-preconditioned CG")
    parser.add_argument("--keep", help="case directory to keep (default: a temporary one, removed)")
    args = parser.parse_args()
    require_openfoam("openfoam_cavity.py")
    n, nu = args.cells, 1.0 / args.re
    case = args.keep or tempfile.mkdtemp(prefix="of_cavity_")
    if args.keep and os.path.exists(case):
        shutil.rmtree(case)
    if args.solver == "ico":
        if args.end is None:
            sys.exit("openfoam_cavity.py: --solver ico needs --end (simulated time)")
        dt = args.dt or 1.0 / n
        steps = int(round(args.end / dt))
        app = "icoFoam"
    else:
        dt, steps, app = 1.0, args.iterations, "simpleFoam"
    write_case(case, n, nu, args.solver, dt, steps, args.procs, args.loose, args.gamg)
    run(case, ["blockMesh"], "log.blockMesh")
    seconds = solve(case, app, args.procs)
    last = latest_time(case)
    field = read_velocity(case, last, n)
    change = float("nan")
    if args.solver == "ico":
        # One step more, serial from the reconstructed last time and written, for
        # max|u(t) - u(t - dt)| / dt (Monolith's steady-state measure).
        for k in range(args.procs if args.procs > 1 else 0):
            shutil.rmtree(os.path.join(case, f"processor{k}"))
        write_case(case, n, nu, args.solver, dt, steps + 1, 1, args.loose, args.gamg, write_every=1)
        run(case, [app], "log.extraStep")
        after = read_velocity(case, latest_time(case), n)
        change = max(max(abs(a[0] - b[0]), abs(a[1] - b[1])) for ra, rb in zip(after, field) for a, b in zip(ra, rb)) / dt
    else:
        steps = int(float(last))
    worst_u, worst_v = ghia_deviation(field, n, args.re)
    print("| code | Re | cells | solver | procs | dt | steps | simulated t | wall s | ms/step | max abs(du)/dt last step | max abs(u - Ghia) | max abs(v - Ghia) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    sim_t = f"{steps * dt:.2f}" if args.solver == "ico" else "steady"
    dt_text = f"{dt:.6g}" if args.solver == "ico" else "-"
    print(f"| OpenFOAM v1912 {app} | {args.re} | {n}^2 | {args.solver}{' (loose)' if args.loose else ''}{', GAMG' if args.gamg else ''} | {args.procs} | {dt_text} | {steps} | {sim_t} | "
          f"{seconds:.1f} | {1000 * seconds / steps:.2f} | {change:.2e} | {worst_u:.4f} | {worst_v:.4f} |")
    if not args.keep:
        shutil.rmtree(case)


if __name__ == "__main__":
    main()
