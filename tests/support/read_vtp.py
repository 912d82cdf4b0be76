#!/usr/bin/python3
"""Reads Monolith's VTK output back with VTK's own readers and prints it as JSON.

usage: read_vtp.py FILE...   (FILE: *.vtp or *.pvd)

Prints one JSON object {"files": {FILE: {...}}, "vtk_version": "..."} on stdout.

  *.vtp  read with vtk.vtkXMLPolyDataReader (the reader ParaView uses):
         number_of_points/verts/polys/lines, bounds (VTK's GetBounds), points [[x,y,z],...],
         polys and lines [[point ids],...], and point_data and cell_data {array name: {class,
         components, tuples, values}} where values are a flat list for one component, a list
         of tuples otherwise and a list of str for a vtkStringArray.
  *.pvd  read with vtkPVDReader when this VTK has it (it is ParaView's), else parsed as XML:
         reader, timesteps, files, files_exist.

Every file also gets "vtk_messages": the errors and warnings VTK printed while reading it
(captured through a vtkStringOutputWindow), so a caller can require a clean read.

Exit codes: 0 ok, 77 the vtk module cannot be imported (the caller may skip), 1 other errors.
Floats go through Python's repr, which round-trips doubles exactly.
"""
import json
import os
import sys
import xml.etree.ElementTree as ET

try:
    import vtk
except ImportError as e:  # pragma: no cover - depends on the machine
    sys.stderr.write("read_vtp.py: cannot import vtk (%s); use the python that has python3-vtk\n" % e)
    sys.exit(77)


def capture_messages():
    window = vtk.vtkStringOutputWindow()
    vtk.vtkOutputWindow.SetInstance(window)
    return window


def array_json(array):
    components = array.GetNumberOfComponents()
    tuples = array.GetNumberOfTuples()
    out = {"class": array.GetClassName(), "components": components, "tuples": tuples}
    if isinstance(array, vtk.vtkStringArray):
        out["values"] = [array.GetValue(i) for i in range(array.GetNumberOfValues())]
    elif components == 1:
        out["values"] = [array.GetComponent(i, 0) for i in range(tuples)]
    else:
        out["values"] = [[array.GetComponent(i, c) for c in range(components)] for i in range(tuples)]
    return out


def read_vtp(path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    poly = reader.GetOutput()
    out = {
        "reader": "vtkXMLPolyDataReader",
        "number_of_points": poly.GetNumberOfPoints(),
        "number_of_verts": poly.GetNumberOfVerts(),
        "number_of_polys": poly.GetNumberOfPolys(),
        "bounds": list(poly.GetBounds()),
        "points": [list(poly.GetPoint(i)) for i in range(poly.GetNumberOfPoints())],
    }
    polys = []
    cells = poly.GetPolys()
    cells.InitTraversal()
    ids = vtk.vtkIdList()
    while cells.GetNextCell(ids):
        polys.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    out["polys"] = polys
    out["number_of_lines"] = poly.GetNumberOfLines()
    lines = []
    cells = poly.GetLines()
    cells.InitTraversal()
    while cells.GetNextCell(ids):
        lines.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    out["lines"] = lines
    for key, data in (("point_data", poly.GetPointData()), ("cell_data", poly.GetCellData())):
        out[key] = {}
        for i in range(data.GetNumberOfArrays()):
            array = data.GetAbstractArray(i)
            out[key][array.GetName()] = array_json(array)
    return out


def read_pvd(path):
    out = {}
    if hasattr(vtk, "vtkPVDReader"):  # ParaView's python, not plain VTK
        reader = vtk.vtkPVDReader()
        reader.SetFileName(path)
        reader.UpdateInformation()
        out["reader"] = "vtkPVDReader"
        out["timesteps"] = [reader.GetTimeStep(i) for i in range(reader.GetNumberOfTimeSteps())]
    root = ET.parse(path).getroot()
    if root.get("type") != "Collection":
        raise ValueError("%s: VTKFile type is %r, not 'Collection'" % (path, root.get("type")))
    datasets = root.findall("./Collection/DataSet")
    if "reader" not in out:
        out["reader"] = "xml"
        out["timesteps"] = [float(d.get("timestep")) for d in datasets]
    out["files"] = [d.get("file") for d in datasets]
    base = os.path.dirname(os.path.abspath(path))
    out["files_exist"] = [os.path.isfile(os.path.join(base, f)) for f in out["files"]]
    return out


def main(argv):
    if len(argv) < 2:
        sys.stderr.write(__doc__)
        return 1
    result = {"vtk_version": vtk.vtkVersion.GetVTKVersion(), "files": {}}
    for path in argv[1:]:
        if not os.path.isfile(path):
            sys.stderr.write("read_vtp.py: no such file %s\n" % path)
            return 1
        window = capture_messages()  # a fresh window per file: messages of this file only
        entry = read_pvd(path) if path.endswith(".pvd") else read_vtp(path)
        entry["vtk_messages"] = window.GetOutput()
        result["files"][path] = entry
    json.dump(result, sys.stdout)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
