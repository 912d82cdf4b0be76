#!/usr/bin/env python3
"""DFG 2D-2 (Schaefer & Turek 1996, Re 100, periodic) in OpenFOAM, as a finite-volume baseline
for Monolith's dfg_2d2 scene at similar cell counts (docs/benchmarks.md, DFG 2D-2 section).

The mesh is body-fitted, as an OpenFOAM user would build it: blockMesh with an O-grid of four
blocks between the disk (r = 0.05 at (0.2, 0.2)) and the square [0.1, 0.3]^2, and eight
Cartesian blocks for the rest of the channel [0, 2.2] x [0, 0.41]. At level L the bulk spacing
is 0.01 / L (the spacing of Monolith's 220 L x 41 L grid), the disk has 80 L faces around it and
10 L cells across the O-grid, graded 4:1 towards the disk; L = 1 has 9 420 cells (Monolith's
220 x 41: 9 020).

icoFoam (transient PISO, Euler, central differencing, 2 correctors + 1 non-orthogonal
corrector), inflow u = 4 U y (0.41 - y) / 0.41^2 with U = 1.5, p = 0 and zero-gradient velocity
at the outflow, no-slip channel walls and disk, nu = 0.001, dt = 0.002 / L, to t = --end.
Forces by OpenFOAM's forceCoeffs function object (c = 2 F / (rho Ubar^2 D), Ubar = 1, D = 0.1);
c_D,max, c_L,max and the lift's period (mean up-crossings) over t >= --from, as bench_dfg 2d2
measures them.

Needs OpenFOAM (Debian 12: `apt-get install openfoam`, v1912). Not part of CI.
Usage: /usr/bin/python3 scenarios/comparisons/openfoam_dfg2d2.py --level 1 [--end 12] [--from 6]
           [--procs 2] [--keep DIR]
"""
import argparse
import math
import os
import re
import shutil
import tempfile

from openfoam_case import HEADER, require_openfoam, run, solve, write
H, R, CX, CY, PEAK, NU, SPAN = 0.41, 0.05, 0.2, 0.2, 1.5, 0.001, 0.01
# Wake points on the centre line: the recirculation just behind the disk (x = 0.26 ... 0.4) and the
# shedding's strength further away (0.6, 1.0).
PROBES = [(0.26, 0.2), (0.3, 0.2), (0.35, 0.2), (0.4, 0.2), (0.6, 0.2), (1.0, 0.2)]
REF_CD, REF_CL, REF_ST = 3.23, 1.00, 0.300  # REFERENCES.md: c_D,max ~ 3.23, c_L,max ~ 1.00, St in [0.295, 0.305]


def block_mesh(level):
    xs, ys = [0.0, 0.1, 0.3, 2.2], [0.0, 0.1, 0.3, H]
    nx, ny = [10 * level, 20 * level, 190 * level], [10 * level, 20 * level, 11 * level]
    ring_cells, ring_grading = 10 * level, 0.25  # square -> disk: cells shrink 4:1 towards the disk
    vertices = []

    def vertex(x, y):
        vertices.append((x, y))
        return len(vertices) - 1

    grid = {(i, j): vertex(xs[i], ys[j]) for j in range(4) for i in range(4)}
    s = R / math.sqrt(2)
    circle = [vertex(CX - s, CY - s), vertex(CX + s, CY - s), vertex(CX + s, CY + s), vertex(CX - s, CY + s)]
    layer = len(vertices)

    def hexa(a, b, c, e):
        return f"({a} {b} {c} {e} {a + layer} {b + layer} {c + layer} {e + layer})"

    blocks, edges = [], []
    for j in range(3):
        for i in range(3):
            if (i, j) == (1, 1):
                continue
            corners = hexa(grid[i, j], grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1])
            blocks.append(f"hex {corners} ({nx[i]} {ny[j]} 1) simpleGrading (1 1 1)")
    square = [grid[1, 1], grid[2, 1], grid[2, 2], grid[1, 2]]
    for k in range(4):  # O-grid: along the square's side, then from the square in to the disk
        a, b = square[k], square[(k + 1) % 4]
        c, e = circle[(k + 1) % 4], circle[k]
        blocks.append(f"hex {hexa(a, b, c, e)} ({20 * level} {ring_cells} 1) simpleGrading (1 {ring_grading} 1)")
        angle = -math.pi / 2 + k * math.pi / 2  # the arc's midpoint: below, right, above, left
        mid = (CX + R * math.cos(angle), CY + R * math.sin(angle))
        for z, offset in ((0, 0), (SPAN, layer)):
            edges.append(f"arc {c + offset} {e + offset} ({mid[0]!r} {mid[1]!r} {z})")

    def side(a, b):  # a boundary face from bottom-layer vertices a, b
        return f"({a} {b} {b + layer} {a + layer})"

    inlet = [side(grid[0, j], grid[0, j + 1]) for j in range(3)]
    outlet = [side(grid[3, j], grid[3, j + 1]) for j in range(3)]
    walls = [side(grid[i, 0], grid[i + 1, 0]) for i in range(3)] + [side(grid[i, 3], grid[i + 1, 3]) for i in range(3)]
    disk = [side(circle[k], circle[(k + 1) % 4]) for k in range(4)]
    points = "\n".join(f"({x!r} {y!r} 0)" for x, y in vertices) + "\n" + "\n".join(f"({x!r} {y!r} {SPAN})" for x, y in vertices)
    return HEADER.format(cls="dictionary", obj="blockMeshDict") + f"""
scale 1;
vertices
(
{points}
);
blocks
(
{chr(10).join(blocks)}
);
edges
(
{chr(10).join(edges)}
);
boundary
(
    inlet {{ type patch; faces ({' '.join(inlet)}); }}
    outlet {{ type patch; faces ({' '.join(outlet)}); }}
    walls {{ type wall; faces ({' '.join(walls)}); }}
    cylinder {{ type wall; faces ({' '.join(disk)}); }}
);
defaultPatch {{ name frontAndBack; type empty; }}
"""


def block_mesh_uniform(level):
    """One uniform block, 220 L x 41 L: Monolith's grid. The disk is cut out afterwards
    (topoSet + subsetMesh): cells whose centre lies inside it are removed, the faces this exposes
    become the no-slip patch `cylinder` - the finite-volume twin of the thesis's staircase disk."""
    nx, ny = 220 * level, 41 * level
    return HEADER.format(cls="dictionary", obj="blockMeshDict") + f"""
scale 1;
vertices ((0 0 0) (2.2 0 0) (2.2 {H} 0) (0 {H} 0) (0 0 {SPAN}) (2.2 0 {SPAN}) (2.2 {H} {SPAN}) (0 {H} {SPAN}));
blocks (hex (0 1 2 3 4 5 6 7) ({nx} {ny} 1) simpleGrading (1 1 1));
boundary
(
    inlet {{ type patch; faces ((0 4 7 3)); }}
    outlet {{ type patch; faces ((1 2 6 5)); }}
    walls {{ type wall; faces ((0 1 5 4) (3 7 6 2)); }}
    cylinder {{ type wall; faces (); }}
);
defaultPatch {{ name frontAndBack; type empty; }}
"""


def topo_set():
    return HEADER.format(cls="dictionary", obj="topoSetDict") + f"""
actions
(
    {{ name fluid; type cellSet; action new; source cylinderToCell; p1 ({CX} {CY} -1); p2 ({CX} {CY} 1); radius {R}; }}
    {{ name fluid; type cellSet; action invert; }}
);
"""


def read_list(path, pattern):
    with open(path) as f:
        text = f.read()
    start = re.search(r"^\d+\s*\n\(", text, re.M)
    return re.findall(pattern, text[start.start():])


def inlet_profile(case):
    """Parabolic inflow at the inlet's face centres (no compiled boundary condition needed)."""
    points = [tuple(map(float, p)) for p in read_list(f"{case}/constant/polyMesh/points", r"\(([-0-9.eE+]+) ([-0-9.eE+]+) ([-0-9.eE+]+)\)")]
    faces = read_list(f"{case}/constant/polyMesh/faces", r"\d+\(([0-9 ]+)\)")
    with open(f"{case}/constant/polyMesh/boundary") as f:
        boundary = f.read()
    inlet = re.search(r"inlet\s*\{[^}]*nFaces\s+(\d+);[^}]*startFace\s+(\d+);", boundary)
    count, start = int(inlet.group(1)), int(inlet.group(2))
    values = []
    for face in faces[start:start + count]:
        y = sum(points[int(v)][1] for v in face.split()) / len(face.split())
        values.append(f"({4 * PEAK * y * (H - y) / H ** 2!r} 0 0)")
    return f"nonuniform List<vector> {count}\n(\n" + "\n".join(values) + "\n)"


def write_case(case, level, end, procs, staircase):
    dt = 0.002 / level
    write(f"{case}/system/blockMeshDict", block_mesh_uniform(level) if staircase else block_mesh(level))
    if staircase:
        write(f"{case}/system/topoSetDict", topo_set())
    write(f"{case}/system/controlDict", HEADER.format(cls="dictionary", obj="controlDict") + f"""
application icoFoam; startFrom startTime; startTime 0; stopAt endTime; endTime {end!r}; deltaT {dt!r};
writeControl runTime; writeInterval {end!r}; purgeWrite 0; writeFormat ascii; writePrecision 10;
writeCompression off; timeFormat general; timePrecision 10; runTimeModifiable false;
functions
{{
    forces
    {{
        type forceCoeffs; libs ("libforces.so"); writeControl timeStep; writeInterval 1;
        patches (cylinder); rho rhoInf; rhoInf 1; CofR ({CX} {CY} {SPAN / 2}); liftDir (0 1 0);
        dragDir (1 0 0); pitchAxis (0 0 1); magUInf 1; lRef {2 * R}; Aref {2 * R * SPAN!r};
    }}
    probes
    {{
        type probes; libs ("libsampling.so"); writeControl timeStep; writeInterval 1; fields (U);
        probeLocations ({" ".join(f"({x} {y} {SPAN / 2})" for x, y in PROBES)});
    }}
}}
""")
    write(f"{case}/system/fvSchemes", HEADER.format(cls="dictionary", obj="fvSchemes") + """
ddtSchemes { default Euler; }
gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
""")
    write(f"{case}/system/fvSolution", HEADER.format(cls="dictionary", obj="fvSolution") + """
solvers
{
    p { solver GAMG; smoother GaussSeidel; tolerance 1e-8; relTol 0.01; }
    pFinal { $p; relTol 0; }
    U { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-9; relTol 0; }
}
PISO { nCorrectors 2; nNonOrthogonalCorrectors 1; pRefCell 0; pRefValue 0; }
""")
    write(f"{case}/system/decomposeParDict", HEADER.format(cls="dictionary", obj="decomposeParDict") +
          f"numberOfSubdomains {procs};\nmethod simple;\ncoeffs {{ n ({procs} 1 1); }}\n")
    write(f"{case}/constant/transportProperties", HEADER.format(cls="dictionary", obj="transportProperties") +
          f"nu [0 2 -1 0 0 0 0] {NU!r};\n")


def write_fields(case):
    write(f"{case}/0/U", HEADER.format(cls="volVectorField", obj="U") + f"""
dimensions [0 1 -1 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{{
    inlet {{ type fixedValue; value {inlet_profile(case)}; }}
    outlet {{ type zeroGradient; }}
    walls {{ type noSlip; }}
    cylinder {{ type noSlip; }}
    frontAndBack {{ type empty; }}
}}
""")
    write(f"{case}/0/p", HEADER.format(cls="volScalarField", obj="p") + """
dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    inlet { type zeroGradient; }
    outlet { type fixedValue; value uniform 0; }
    walls { type zeroGradient; }
    cylinder { type zeroGradient; }
    frontAndBack { type empty; }
}
""")


def coefficients(case):
    """(t, c_D, c_L) rows from forceCoeffs' output."""
    found = []
    for root, _, files in os.walk(os.path.join(case, "postProcessing")):
        found += [os.path.join(root, f) for f in files if f.endswith(".dat")]
    if not found:
        raise RuntimeError(f"{case}: no forceCoeffs output under postProcessing/")
    rows, columns = [], None
    with open(sorted(found)[0]) as f:
        for line in f:
            if line.startswith("#"):
                names = line[1:].split()
                if "Cd" in names and "Cl" in names:
                    columns = names
                continue
            values = line.split()
            if columns and len(values) == len(columns):
                rows.append((float(values[0]), float(values[columns.index("Cd")]), float(values[columns.index("Cl")])))
    return rows


def wake_statistics(case, start):
    """Mean u and half the peak-to-peak v at each wake probe over t >= start."""
    path = os.path.join(case, "postProcessing", "probes", "0", "U")
    samples = [[] for _ in PROBES]
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                continue
            t = float(line.split()[0])
            if t < start:
                continue
            vectors = re.findall(r"\(([-0-9.eE+]+) ([-0-9.eE+]+) [-0-9.eE+]+\)", line)
            for k, v in enumerate(vectors):
                samples[k].append((float(v[0]), float(v[1])))
    return [(sum(u for u, _ in s) / len(s), (max(v for _, v in s) - min(v for _, v in s)) / 2) for s in samples]


def analyse(rows, start):
    window = [r for r in rows if r[0] >= start]
    if len(window) < 10:
        raise RuntimeError("too few force samples after --from")
    cd_max = max(r[1] for r in window)
    cl_max = max(r[2] for r in window)
    mean = sum(r[2] for r in window) / len(window)
    crossings = []
    for a, b in zip(window, window[1:]):
        if a[2] < mean <= b[2]:
            crossings.append(a[0] + (mean - a[2]) / (b[2] - a[2]) * (b[0] - a[0]))
    if len(crossings) < 2:
        return cd_max, cl_max, float("nan"), 0
    period = (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    return cd_max, cl_max, 2 * R / period, len(crossings) - 1  # St = D f / Ubar, Ubar = 1


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--level", type=int, default=1)
    parser.add_argument("--end", type=float, default=12.0)
    parser.add_argument("--from", dest="start", type=float, default=6.0)
    parser.add_argument("--procs", type=int, default=1)
    parser.add_argument("--mesh", choices=("ogrid", "staircase"), default="ogrid",
                        help="body-fitted O-grid (default) or Monolith's uniform grid with the disk's cells removed")
    parser.add_argument("--keep", help="case directory to keep (default: a temporary one, removed)")
    args = parser.parse_args()
    require_openfoam("openfoam_dfg2d2.py")
    case = args.keep or tempfile.mkdtemp(prefix="of_dfg_")
    if args.keep and os.path.exists(case):
        shutil.rmtree(case)
    write_case(case, args.level, args.end, args.procs, args.mesh == "staircase")
    run(case, ["blockMesh"], "log.blockMesh")
    if args.mesh == "staircase":
        run(case, ["topoSet"], "log.topoSet")
        run(case, ["subsetMesh", "fluid", "-patch", "cylinder", "-overwrite"], "log.subsetMesh")
    run(case, ["checkMesh"], "log.checkMesh")
    cells = int(re.search(r"cells:\s+(\d+)", open(os.path.join(case, "log.checkMesh")).read()).group(1))
    write_fields(case)
    seconds = solve(case, "icoFoam", args.procs)
    cd_max, cl_max, st, periods = analyse(coefficients(case), args.start)
    steps = int(round(args.end / (0.002 / args.level)))
    print("| code | level | cells | dt | steps | processes | wall s | ms/step | c_D,max | err | c_L,max | err | St | err (vs 0.300) | periods |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    print(f"| OpenFOAM v1912 icoFoam, {'O-grid' if args.mesh == 'ogrid' else 'staircase'} | {args.level} | {cells} | {0.002 / args.level:g} | {steps} | {args.procs} | "
          f"{seconds:.1f} | {1000 * seconds / steps:.2f} | {cd_max:.4f} | {100 * (cd_max / REF_CD - 1):+.1f} % | "
          f"{cl_max:.4f} | {100 * (cl_max / REF_CL - 1):+.1f} % | {st:.4f} | {100 * (st / REF_ST - 1):+.1f} % | {periods} |")
    print(f"wake probes over t >= {args.start:g}: (x, y): mean u, v amplitude (half peak-to-peak)")
    for (x, y), (mean_u, amplitude) in zip(PROBES, wake_statistics(case, args.start)):
        print(f"  ({x}, {y}): {mean_u:.4f}, {amplitude:.4f}")
    if not args.keep:
        shutil.rmtree(case)


if __name__ == "__main__":
    main()
