#!/usr/bin/python3
"""Reads a Monolith .vti fluid frame with VTK's own reader and prints, as JSON, the dimensions,
spacing, origin, the cell-data array names and the values of the "velocity" (3 components) and
"pressure" arrays. Exit 77 when the vtk module cannot be imported."""
import json
import sys

try:
    import vtk
except ImportError as e:
    sys.stderr.write("read_vti.py: cannot import vtk (%s)\n" % e)
    sys.exit(77)

reader = vtk.vtkXMLImageDataReader()
reader.SetFileName(sys.argv[1])
reader.Update()
image = reader.GetOutput()
cells = image.GetCellData()
out = {
    "dimensions": list(image.GetDimensions()),
    "spacing": list(image.GetSpacing()),
    "origin": list(image.GetOrigin()),
    "arrays": [cells.GetArrayName(i) for i in range(cells.GetNumberOfArrays())],
    "cells": image.GetNumberOfCells(),
}
for name in ("velocity", "pressure"):
    array = cells.GetArray(name)
    out[name] = [list(array.GetTuple(i)) for i in range(array.GetNumberOfTuples())] if array else None
print(json.dumps(out))
