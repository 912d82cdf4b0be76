#!/usr/bin/python3
"""Render one frame of a Monolith run directory to a PNG (`monolith plot RUN --frame`, docs/tools.md).

Reads the run's ParaView output with Debian's python3-vtk9 and draws it with python3-matplotlib
(Agg backend: no display, no OpenGL needed):
- a 2-D fluid (fluid.pvd): the chosen cell field (speed, vorticity, pressure, ...) as an image,
  solid cells blank, with the bodies' and deformables' outlines on top; a 3-D fluid is shown on
  its middle z slice;
- 3-D bodies and deformables without a fluid (geometry.pvd, deformables.pvd): their surfaces
  seen by an orthographic camera (--view azimuth,elevation in degrees), faces shaded by their
  angle to the light and drawn back to front; a large flat body (a ground plane) is drawn first
  and the other bodies without mass (walls, fixed or scripted bodies) are see-through;
- 2-D bodies and deformables without a fluid: filled outlines in the plane.
The frame is the one nearest --time (default: the last frame written).
"""
import argparse
import math
import os
import sys
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402

# Collections drawn as surfaces; fluid.pvd is drawn as a field.
SURFACE_COLLECTIONS = ("geometry.pvd", "deformables.pvd")
FIELDS = ("speed", "vorticity", "pressure", "divergence", "u", "v", "w")


def fail(message):
    sys.exit("monolith plot --frame: " + message)


def vtk_modules():
    try:
        import vtk  # noqa: F401
        from vtk.util.numpy_support import vtk_to_numpy
    except ImportError:
        fail("needs python3-vtk9 (apt-get install python3-vtk9; cmake/install-deps.sh installs it)")
    return vtk, vtk_to_numpy


def collection(run, name):
    """[(time, file)] of a .pvd collection, in time order; [] if the run has none."""
    path = os.path.join(run, name)
    if not os.path.exists(path):
        return []
    entries = []
    for ds in ET.parse(path).getroot().iter("DataSet"):
        entries.append((float(ds.get("timestep")), os.path.join(run, ds.get("file"))))
    return sorted(entries)


def nearest(entries, time):
    if time is None:
        return entries[-1]
    return min(entries, key=lambda e: abs(e[0] - time))


def read(path):
    vtk, _ = vtk_modules()
    readers = {".vtp": vtk.vtkXMLPolyDataReader, ".vtu": vtk.vtkXMLUnstructuredGridReader,
               ".vti": vtk.vtkXMLImageDataReader}
    ext = os.path.splitext(path)[1]
    if ext not in readers or not os.path.exists(path):
        fail("cannot read frame file %s" % path)
    reader = readers[ext]()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def surfaces(dataset):
    """Polygons and polylines of a data set's outer surface: ([(points, body)], [(points, body)])."""
    vtk, vtk_to_numpy = vtk_modules()
    if not isinstance(dataset, vtk.vtkPolyData):
        f = vtk.vtkGeometryFilter()
        f.SetInputData(dataset)
        f.Update()
        dataset = f.GetOutput()
    if dataset.GetNumberOfPoints() == 0:
        return [], []
    pts = vtk_to_numpy(dataset.GetPoints().GetData()).astype(float)
    ids = None
    for name in ("body_id", "body"):
        a = dataset.GetPointData().GetArray(name)
        if a is not None:
            ids = vtk_to_numpy(a).astype(int)
            break

    def cells(array):
        out = []
        array.InitTraversal()
        idl = vtk.vtkIdList()
        while array.GetNextCell(idl):
            idx = [idl.GetId(i) for i in range(idl.GetNumberOfIds())]
            out.append((pts[idx], int(ids[idx[0]]) if ids is not None else 0))
        return out

    return cells(dataset.GetPolys()), cells(dataset.GetLines())


def static_bodies(run, time):
    """Ids of the rigid bodies without mass (static or kinematic) in the frame nearest `time`."""
    entries = collection(run, "bodies.pvd")
    if not entries:
        return set()
    _, vtk_to_numpy = vtk_modules()
    data = read(nearest(entries, time)[1]).GetPointData()
    ids, mass = data.GetArray("id"), data.GetArray("mass")
    if ids is None or mass is None:
        return set()
    return {int(i) for i, m in zip(vtk_to_numpy(ids), vtk_to_numpy(mass)) if m == 0}


def frame_surfaces(run, time):
    polys, lines, times = [], [], []
    for offset, name in enumerate(SURFACE_COLLECTIONS):
        entries = collection(run, name)
        if not entries:
            continue
        t, path = nearest(entries, time)
        p, l = surfaces(read(path))
        # Deformables get body numbers of their own so that they do not share the rigid colours.
        polys += [(pt, b + 1000 * offset) for pt, b in p]
        lines += [(pt, b + 1000 * offset) for pt, b in l]
        times.append(t)
    return polys, lines, times


def body_colour(body):
    return plt.get_cmap("tab20")((body * 7) % 20)


def draw_outlines_2d(ax, polys, lines, filled):
    if polys:
        faces = [p[:, :2] for p, _ in polys]
        colours = [body_colour(b) if filled else (0.82, 0.82, 0.82, 1.0) for _, b in polys]
        ax.add_collection(PolyCollection(faces, facecolors=colours, edgecolors="0.15", linewidths=0.4))
    if lines:
        ax.add_collection(LineCollection([p[:, :2] for p, _ in lines], colors="0.1", linewidths=1.0))


def newell_normal(p):
    n = np.zeros(3)
    for i in range(len(p)):
        a, b = p[i], p[(i + 1) % len(p)]
        n += [(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1])]
    length = np.linalg.norm(n)
    return n / length if length > 0 else n


def polygon_area(p):
    n = np.zeros(3)
    for i in range(len(p)):
        n += np.cross(p[i], p[(i + 1) % len(p)])
    return 0.5 * np.linalg.norm(n)


def ground_bodies(polys):
    """Bodies drawn as one polygon covering a fifth or more of the scene's extent (ground planes)."""
    if not polys:
        return set()
    span = np.ptp(np.vstack([p for p, _ in polys]), axis=0)
    scene_area = max(span[0] * span[2], span[0] * span[1], span[1] * span[2], 1e-12)
    faces_of = {}
    for p, b in polys:
        faces_of[b] = faces_of.get(b, 0) + 1
    return {b for p, b in polys if faces_of[b] == 1 and polygon_area(p) > 0.2 * scene_area}


def draw_3d(ax, polys, lines, azimuth, elevation, static=frozenset()):
    az, el = math.radians(azimuth), math.radians(elevation)
    toward_camera = np.array([math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)])
    right = np.cross([0.0, 1.0, 0.0], toward_camera)
    right /= np.linalg.norm(right)
    up = np.cross(toward_camera, right)
    light = toward_camera + np.array([0.3, 0.8, 0.2])
    light /= np.linalg.norm(light)

    centroids = {}
    for p, b in polys:
        centroids.setdefault(b, []).append(p)
    centroids = {b: np.vstack(ps).mean(axis=0) for b, ps in centroids.items()}
    # A body of one large flat face is the ground: drawn first, not counted in the view's extent.
    ground = ground_bodies(polys)

    items = []
    for p, b in polys:
        n = newell_normal(p)
        if b not in ground:
            # Convex bodies: orient the normal away from the body's centre, cull faces turned away.
            if np.dot(n, p.mean(axis=0) - centroids[b]) < 0:
                n = -n
            if np.dot(n, toward_camera) <= 0:
                continue
        shade = 0.35 + 0.65 * abs(float(np.dot(n, light)))
        if b in ground:
            colour = (0.78, 0.78, 0.76, 1.0)
        elif b in static:
            colour = (0.6, 0.65, 0.75, 0.18)  # walls and fixed bodies: see-through
        else:
            colour = body_colour(b)
        colour = tuple(min(1.0, c * shade) for c in colour[:3]) + (colour[3],)
        depth = -1e300 if b in ground else float(np.mean(p @ toward_camera))
        items.append((depth, np.column_stack([p @ right, p @ up]), colour))
    items.sort(key=lambda i: i[0])
    ax.add_collection(PolyCollection([i[1] for i in items], facecolors=[i[2] for i in items],
                                     edgecolors=(0, 0, 0, 0.2), linewidths=0.25))
    if lines:
        ax.add_collection(LineCollection([np.column_stack([p @ right, p @ up]) for p, _ in lines],
                                         colors="0.1", linewidths=0.8))
    body_pts = [np.column_stack([p @ right, p @ up]) for p, b in polys if b not in ground]
    pts2 = np.vstack(body_pts) if body_pts else np.vstack([i[1] for i in items])
    lo, hi = pts2.min(axis=0), pts2.max(axis=0)
    margin = 0.08 * max(hi - lo)
    ax.set_xlim(lo[0] - margin, hi[0] + margin)
    ax.set_ylim(lo[1] - margin, hi[1] + margin)


def cell_field(image, field):
    """(values as a ny x nx array of the middle z slice, solid mask, extent) of a fluid frame."""
    _, vtk_to_numpy = vtk_modules()
    e = image.GetExtent()
    n = [max(e[1] - e[0], 1), max(e[3] - e[2], 1), max(e[5] - e[4], 1)]
    origin, spacing = image.GetOrigin(), image.GetSpacing()
    cd = image.GetCellData()

    def array(name):
        a = cd.GetArray(name)
        if a is None:
            names = [cd.GetArrayName(i) for i in range(cd.GetNumberOfArrays())]
            fail("the fluid frame has no '%s' (it has %s)" % (name, ", ".join(names)))
        v = vtk_to_numpy(a).astype(float)
        return v.reshape(n[2], n[1], n[0], -1)[n[2] // 2]

    vel = array("velocity")
    if field == "speed":
        values = np.linalg.norm(vel, axis=-1)
    elif field in ("u", "v", "w"):
        values = vel[..., "uvw".index(field)]
    elif field == "vorticity":
        w = array("vorticity")
        values = w[..., -1] if w.shape[-1] > 1 else w[..., 0]  # 3-D: the z component
    else:
        values = array(field)[..., 0]
    solid = cd.GetArray("solid")
    mask = array("solid")[..., 0] > 0.5 if solid is not None else np.zeros(values.shape, bool)
    extent = (origin[0], origin[0] + n[0] * spacing[0], origin[1], origin[1] + n[1] * spacing[1])
    return values, mask, extent


def render(run, time=None, field="speed", view=(-35.0, 25.0), out=None, title=None):
    if not os.path.isdir(run):
        fail("%s is not a run directory" % run)
    fluid = collection(run, "fluid.pvd")
    polys, lines, times = frame_surfaces(run, time)
    if not fluid and not polys and not lines:
        fail("%s has no frames (fluid.pvd, geometry.pvd or deformables.pvd; was it run with --no-frames?)" % run)
    if field not in FIELDS:
        fail("unknown field '%s' (one of %s)" % (field, ", ".join(FIELDS)))
    out = out or os.path.join(run, "frame.png")
    if title is None:
        title = os.path.basename(os.path.normpath(run))

    if fluid:
        t, path = nearest(fluid, time)
        values, mask, extent = cell_field(read(path), field)
        width, height = extent[1] - extent[0], extent[3] - extent[2]
        aspect = height / width
        fig, ax = plt.subplots(figsize=(8.0, max(2.2, min(8.0, 8.0 * aspect + 0.9))))
        data = np.ma.masked_array(values, mask)
        if field == "vorticity":
            lim = float(np.percentile(np.abs(data.compressed()), 99)) if data.count() else 1.0
            kw = dict(cmap="RdBu_r", vmin=-lim, vmax=lim)
        else:
            kw = dict(cmap="viridis" if field == "speed" else "coolwarm")
        cmap = plt.get_cmap(kw.pop("cmap")).copy()
        cmap.set_bad("0.55")
        im = ax.imshow(data, origin="lower", extent=extent, interpolation="bilinear", cmap=cmap, **kw)
        draw_outlines_2d(ax, polys, lines, filled=False)
        ax.set_xlim(extent[0], extent[1])
        ax.set_ylim(extent[2], extent[3])
        ax.set_aspect("equal")
        fig.colorbar(im, ax=ax, shrink=0.9, pad=0.02, fraction=0.03 if aspect < 0.5 else 0.046).set_label(field)
    else:
        all_pts = np.vstack([p for p, _ in polys + lines])
        t = max(times)
        flat = np.ptp(all_pts[:, 2]) == 0 and np.all(all_pts[:, 2] == 0)
        fig, ax = plt.subplots(figsize=(8.0, 5.0))
        if flat:
            draw_outlines_2d(ax, polys, lines, filled=True)
            # The view frames the bodies; a ground (one large polygon) is cut at the margin.
            ground = ground_bodies(polys)
            shown = [p for p, b in polys + lines if b not in ground] or [p for p, _ in polys + lines]
            pts = np.vstack(shown)
            lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
            margin = 0.15 * max(hi - lo)
            ax.set_xlim(lo[0] - margin, hi[0] + margin)
            ax.set_ylim(lo[1] - margin, hi[1] + margin)
        else:
            draw_3d(ax, polys, lines, view[0], view[1], static_bodies(run, time))
        ax.set_aspect("equal")
        ax.set_axis_off()
    ax.set_title("%s, t = %.3g s" % (title, t), fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


def main(argv=None):
    p = argparse.ArgumentParser(prog="render_frame.py", description=__doc__.split("\n\n")[0])
    p.add_argument("run", help="a run directory written with frames")
    p.add_argument("--time", type=float, help="the frame nearest this time (default: the last)")
    p.add_argument("--field", default="speed", help="fluid cell field: " + ", ".join(FIELDS))
    p.add_argument("--view", default="-35,25", help="3-D camera azimuth,elevation in degrees")
    p.add_argument("--title")
    p.add_argument("--out")
    a = p.parse_args(argv)
    try:
        view = tuple(float(v) for v in a.view.split(","))
        assert len(view) == 2
    except (ValueError, AssertionError):
        fail("--view expects azimuth,elevation in degrees, got '%s'" % a.view)
    print(render(a.run, a.time, a.field, view, a.out, a.title))


if __name__ == "__main__":
    main()
