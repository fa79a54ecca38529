#!/usr/bin/env python3
"""Independent check of a VTK file with meshio (https://pypi.org/project/meshio/).

Reads FILE with meshio (not with unamalla's own reader) and compares it with the expected
counts. Prints a JSON summary on stdout; on any mismatch prints the problems on stderr and
exits with status 1 (status 2 for usage errors or when meshio cannot read the file).

With --dump, the points, cells and cell arrays meshio read are also written to a JSON file
(floats as repr strings) so that the caller can compare them with what it wrote.

Example:
    python3 scripts/check_vtk_meshio.py mesh.vtk --points 20 --cells 12 \
        --cell-type quad --cell-array quality --cell-array block
"""

import argparse
import json
import math
import sys


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", help="VTK file to check")
    ap.add_argument("--points", type=int, required=True, help="expected number of points")
    ap.add_argument("--cells", type=int, required=True, help="expected number of cells")
    ap.add_argument(
        "--cell-type",
        required=True,
        choices=["quad", "hexahedron"],
        help="expected meshio cell type of every cell",
    )
    ap.add_argument(
        "--cell-array",
        action="append",
        default=[],
        metavar="NAME",
        help="a cell data array that must exist with one finite value per cell (repeatable)",
    )
    ap.add_argument(
        "--dump",
        metavar="JSON",
        help="also write what meshio read to this JSON file: points, cells (per block) and cell "
        "arrays, with every float as its shortest round-trip string (repr) so that a caller "
        "can compare values bit for bit",
    )
    ap.add_argument(
        "--planar",
        action="store_true",
        help="also require every z coordinate to be 0",
    )
    args = ap.parse_args()

    try:
        import meshio  # noqa: PLC0415 (imported late so that --help works without meshio)
    except ImportError:
        print("error: meshio is not installed (pip install meshio)", file=sys.stderr)
        return 2

    try:
        mesh = meshio.read(args.file)
    except Exception as e:  # meshio raises many exception types
        print(f"error: meshio could not read {args.file}: {e}", file=sys.stderr)
        return 2

    problems = []
    points = mesh.points
    n_points = int(points.shape[0])
    if n_points != args.points:
        problems.append(f"points: expected {args.points}, meshio read {n_points}")
    if not all(math.isfinite(float(v)) for v in points.ravel()):
        problems.append("points: non-finite coordinate")
    if args.planar and points.shape[1] >= 3:
        nonzero = [i for i, z in enumerate(points[:, 2]) if float(z) != 0.0]
        if nonzero:
            problems.append(f"planar: {len(nonzero)} point(s) with z != 0, first {nonzero[0]}")

    cell_types = {}
    n_cells = 0
    for block in mesh.cells:
        cell_types[block.type] = cell_types.get(block.type, 0) + len(block.data)
        n_cells += len(block.data)
    if n_cells != args.cells:
        problems.append(f"cells: expected {args.cells}, meshio read {n_cells}")
    wrong = {t: c for t, c in cell_types.items() if t != args.cell_type}
    if wrong:
        problems.append(f"cell types: expected only {args.cell_type!r}, found {wrong}")
    for block in mesh.cells:
        if len(block.data) and (block.data.min() < 0 or block.data.max() >= n_points):
            problems.append(f"cells of type {block.type}: node index out of range")

    arrays = {}
    for name, blocks in mesh.cell_data.items():
        values = [float(v) for b in blocks for v in list(b.ravel())]
        finite = [v for v in values if math.isfinite(v)]
        arrays[name] = {
            "len": len(values),
            "min": min(finite) if finite else None,
            "max": max(finite) if finite else None,
            "non_finite": len(values) - len(finite),
        }
    for name in args.cell_array:
        info = arrays.get(name)
        if info is None:
            problems.append(f"cell array {name!r}: missing (meshio found {sorted(arrays)})")
            continue
        if info["len"] != args.cells:
            problems.append(f"cell array {name!r}: {info['len']} values for {args.cells} cells")
        if info["non_finite"]:
            problems.append(f"cell array {name!r}: {info['non_finite']} non-finite value(s)")

    summary = {
        "file": args.file,
        "meshio_version": getattr(meshio, "__version__", "unknown"),
        "points": n_points,
        "cells": n_cells,
        "cell_types": cell_types,
        "cell_arrays": arrays,
        "point_arrays": sorted(mesh.point_data),
        "ok": not problems,
        "problems": problems,
    }
    if args.dump:
        dump = {
            "points": [[repr(float(c)) for c in p] for p in points],
            "cells": [
                {"type": b.type, "data": [[int(v) for v in row] for row in b.data]}
                for b in mesh.cells
            ],
            "cell_data": {
                name: [repr(float(v)) for b in blocks for v in list(b.ravel())]
                for name, blocks in mesh.cell_data.items()
            },
        }
        with open(args.dump, "w", encoding="utf-8") as f:
            json.dump(dump, f)
    print(json.dumps(summary, indent=2, sort_keys=True))
    for p in problems:
        print(f"mismatch: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
