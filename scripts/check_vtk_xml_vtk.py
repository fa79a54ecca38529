#!/usr/bin/env python3
"""Independent check of a VTK XML file (.vts, .vtu, .vtm) with VTK's own readers (PyPI `vtk`).

meshio (scripts/check_vtk_meshio.py) reads .vtu but has no .vts or .vtm reader, so structured
blocks and multiblock indexes are checked with the reference implementation: VTK's
vtkXMLStructuredGridReader, vtkXMLUnstructuredGridReader and vtkXMLMultiBlockDataReader (the
readers ParaView uses). Any VTK error or warning while reading is a failure.

Prints a JSON summary on stdout; on any mismatch prints the problems on stderr and exits with
status 1 (status 2 for usage errors or when the `vtk` package is missing). With --dump, the
points and cell arrays VTK read (floats as repr strings) are written to a JSON file so that the
caller can compare them bit for bit; for a .vtm they are concatenated over the blocks.

Example:
    python3 scripts/check_vtk_xml_vtk.py block-0.vts --points 12 --cells 6 \
        --cell-type quad --dims 4 3 1 --cell-array quality
    python3 scripts/check_vtk_xml_vtk.py blocks.vtm --blocks 2 --points 21 --cells 10 \
        --cell-type quad
"""

import argparse
import json
import math
import sys

CELL_TYPES = {"quad": 9, "hexahedron": 12}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", help=".vts, .vtu or .vtm file to check")
    ap.add_argument("--points", type=int, required=True, help="expected number of points (sum over blocks for .vtm)")
    ap.add_argument("--cells", type=int, required=True, help="expected number of cells (sum over blocks for .vtm)")
    ap.add_argument("--cell-type", required=True, choices=sorted(CELL_TYPES), help="expected type of every cell")
    ap.add_argument("--cell-array", action="append", default=[], metavar="NAME",
                    help="a one-component cell array that must exist in every data set (repeatable)")
    ap.add_argument("--dims", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                    help="expected point dimensions of a .vts")
    ap.add_argument("--blocks", type=int, help="expected number of blocks of a .vtm")
    ap.add_argument("--planar", action="store_true", help="also require every z coordinate to be 0")
    ap.add_argument("--dump", metavar="JSON", help="write the points and cell arrays VTK read to this file")
    args = ap.parse_args()

    try:
        from vtkmodules.vtkCommonCore import vtkObject  # noqa: PLC0415
        from vtkmodules.vtkIOXML import (  # noqa: PLC0415
            vtkXMLMultiBlockDataReader,
            vtkXMLStructuredGridReader,
            vtkXMLUnstructuredGridReader,
        )
    except ImportError:
        print("error: the vtk package is not installed (pip install vtk)", file=sys.stderr)
        return 2

    vtkObject.GlobalWarningDisplayOff()
    ext = args.file.rsplit(".", 1)[-1].lower()
    readers = {
        "vts": vtkXMLStructuredGridReader,
        "vtu": vtkXMLUnstructuredGridReader,
        "vtm": vtkXMLMultiBlockDataReader,
    }
    if ext not in readers:
        print(f"error: unknown extension .{ext}", file=sys.stderr)
        return 2
    reader = readers[ext]()
    events = []

    def on_event(obj, event):
        events.append(event)

    reader.AddObserver("ErrorEvent", on_event)
    reader.AddObserver("WarningEvent", on_event)
    reader.SetFileName(args.file)
    reader.Update()
    output = reader.GetOutput()

    problems = []
    if events:
        problems.append(f"VTK reported {events}")
    datasets = []
    if ext == "vtm":
        n_blocks = output.GetNumberOfBlocks()
        if args.blocks is not None and n_blocks != args.blocks:
            problems.append(f"blocks: expected {args.blocks}, VTK read {n_blocks}")
        for b in range(n_blocks):
            ds = output.GetBlock(b)
            if ds is None:
                problems.append(f"block {b}: not loaded")
            else:
                datasets.append(ds)
    else:
        datasets.append(output)

    n_points = sum(ds.GetNumberOfPoints() for ds in datasets)
    n_cells = sum(ds.GetNumberOfCells() for ds in datasets)
    if n_points != args.points:
        problems.append(f"points: expected {args.points}, VTK read {n_points}")
    if n_cells != args.cells:
        problems.append(f"cells: expected {args.cells}, VTK read {n_cells}")
    want_type = CELL_TYPES[args.cell_type]
    types = {}
    points = []
    arrays = {name: [] for name in args.cell_array}
    for ds in datasets:
        for c in range(ds.GetNumberOfCells()):
            t = ds.GetCellType(c)
            types[t] = types.get(t, 0) + 1
        for p in range(ds.GetNumberOfPoints()):
            points.append(ds.GetPoint(p))
        cd = ds.GetCellData()
        for name in args.cell_array:
            arr = cd.GetArray(name)
            if arr is None:
                problems.append(f"cell array {name!r}: missing")
                continue
            if arr.GetNumberOfComponents() != 1 or arr.GetNumberOfTuples() != ds.GetNumberOfCells():
                problems.append(f"cell array {name!r}: wrong shape")
            arrays[name].extend(arr.GetValue(k) for k in range(arr.GetNumberOfTuples()))
    if set(types) - {want_type}:
        problems.append(f"cell types: expected only {want_type}, VTK found {types}")
    if not all(math.isfinite(c) for p in points for c in p):
        problems.append("points: non-finite coordinate")
    if args.planar and any(p[2] != 0.0 for p in points):
        problems.append("planar: a point with z != 0")
    if args.dims is not None:
        if ext != "vts":
            problems.append("--dims is only meaningful for .vts")
        else:
            dims = [0, 0, 0]
            output.GetDimensions(dims)
            if dims != args.dims:
                problems.append(f"dims: expected {args.dims}, VTK read {dims}")

    summary = {
        "file": args.file,
        "vtk_version": __import__("vtkmodules.vtkCommonCore", fromlist=["vtkVersion"]).vtkVersion.GetVTKVersion(),
        "points": n_points,
        "cells": n_cells,
        "cell_types": {str(k): v for k, v in types.items()},
        "datasets": len(datasets),
        "ok": not problems,
        "problems": problems,
    }
    if args.dump:
        with open(args.dump, "w", encoding="utf-8") as f:
            json.dump(
                {
                    "points": [[repr(float(c)) for c in p] for p in points],
                    "cell_data": {k: [repr(float(v)) for v in vs] for k, vs in arrays.items()},
                },
                f,
            )
    print(json.dumps(summary, indent=2, sort_keys=True))
    for p in problems:
        print(f"mismatch: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
