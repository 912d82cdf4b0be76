#!/usr/bin/python3
"""Reads a Monolith deformables .vtu frame with VTK's own reader (vtkXMLUnstructuredGridReader,
the one ParaView uses) and prints, as JSON: the number of points and cells, the count of each
cell type (VTK type numbers as strings: "5" triangle, "10" tetrahedron), the point-data and
cell-data array names, and the values of the "velocity" (3 components, per point) and
"volume_ratio" and "strain" (per cell) arrays, plus the errors VTK printed while reading.
Exit 77 when the vtk module cannot be imported."""
import json
import sys

try:
    import vtk
except ImportError as e:
    sys.stderr.write("read_vtu.py: cannot import vtk (%s)\n" % e)
    sys.exit(77)

window = vtk.vtkStringOutputWindow()
vtk.vtkOutputWindow.SetInstance(window)
reader = vtk.vtkXMLUnstructuredGridReader()
reader.SetFileName(sys.argv[1])
reader.Update()
grid = reader.GetOutput()
types = {}
for c in range(grid.GetNumberOfCells()):
    key = str(grid.GetCellType(c))
    types[key] = types.get(key, 0) + 1
points, cells = grid.GetPointData(), grid.GetCellData()
out = {
    "points": grid.GetNumberOfPoints(),
    "cells": grid.GetNumberOfCells(),
    "cell_types": types,
    "point_arrays": [points.GetArrayName(i) for i in range(points.GetNumberOfArrays())],
    "cell_arrays": [cells.GetArrayName(i) for i in range(cells.GetNumberOfArrays())],
    "vtk_messages": window.GetOutput(),
}
for name, data in (("velocity", points), ("volume_ratio", cells), ("strain", cells)):
    array = data.GetArray(name)
    out[name] = [list(array.GetTuple(i)) for i in range(array.GetNumberOfTuples())] if array else None
print(json.dumps(out))
