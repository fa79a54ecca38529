#!/usr/bin/env python3
"""Writes shapefile samples with pyshp (an independent writer and reader, PyPI `pyshp`) and
records how pyshp reads them back, for the comparison test
`crates/unamalla-io/tests/shapefile_pyshp.rs` (see docs/reliability.md).

    pip install pyshp
    python3 scripts/shp_pyshp_sample.py [OUT_DIR]   # default crates/unamalla-io/tests/data/pyshp

For each sample `<name>` it writes `<name>.shp`, `.shx`, `.dbf` (pyshp always writes all three;
our reader uses only the `.shp`) and `<name>.json`: pyshp's reading of the `.shp`, one entry
per shape with its shape type, part start indices and points (x y only) exactly as pyshp
returns them, and pyshp's own grouping of the rings into polygons (outer ring + holes, from its
`__geo_interface__`). Coordinates are printed with `repr`, which round-trips every float, so the
Rust test can compare bit for bit.

The samples: a projected (UTM-like, ~5·10⁵ / 4·10⁶ m) lake with an island, a shape of two
separate islands, a 64-gon with irrational coordinates, a null shape in between (POLYGON file);
the same rings as POLYGONZ and POLYGONM files.
"""
import json
import math
import os
import sys

import shapefile  # pyshp


def circle(cx, cy, r, n, clockwise):
    pts = []
    for k in range(n):
        t = 2 * math.pi * k / n
        pts.append((cx + r * math.cos(t), cy + r * math.sin(t)))
    if clockwise:
        pts.reverse()
    pts.append(pts[0])
    return pts


def shapes():
    e0, n0 = 512345.25, 4123456.75
    # ESRI orientation: outer rings clockwise, holes counter-clockwise.
    lake = [(e0, n0), (e0, n0 + 900.5), (e0 + 1200.125, n0 + 1000.0), (e0 + 1300.0, n0 - 50.0), (e0, n0)]
    island = [(e0 + 400.0, n0 + 300.0), (e0 + 600.0, n0 + 300.0), (e0 + 500.0, n0 + 450.0), (e0 + 400.0, n0 + 300.0)]
    isl_a = circle(e0 + 3000.0, n0, 250.0, 12, True)
    isl_b = circle(e0 + 4000.0, n0 + 100.0, 150.0, 9, True)
    gon = circle(0.1, -0.2, 1.0 / 3.0, 64, True)
    return [[lake, island], None, [isl_a, isl_b], [gon]]


def write(path, kind):
    w = shapefile.Writer(path, shapeType=kind)
    w.field("name", "C")
    for k, rings in enumerate(shapes()):
        if rings is None:
            w.null()
        elif kind == shapefile.POLYGON:
            w.poly(rings)
        elif kind == shapefile.POLYGONZ:
            # z = 10·part, m = point index
            w.polyz([[(x, y, 10.0 * j, float(i)) for i, (x, y) in enumerate(r)] for j, r in enumerate(rings)])
        else:
            w.polym([[(x, y, float(i)) for i, (x, y) in enumerate(r)] for r in rings])
        w.record(f"shape {k}")
    w.close()


def describe(path):
    out = []
    with shapefile.Reader(path) as r:
        for s in r.shapes():
            entry = {"shape_type": s.shapeType, "parts": list(s.parts),
                     "points": [[repr(p[0]), repr(p[1])] for p in s.points]}
            if s.shapeType != shapefile.NULL:
                gi = s.__geo_interface__
                polys = gi["coordinates"] if gi["type"] == "MultiPolygon" else [gi["coordinates"]]
                entry["polygons"] = [{"holes": len(p) - 1, "outer_len": len(p[0])} for p in polys]
            out.append(entry)
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "crates", "unamalla-io", "tests", "data", "pyshp")
    os.makedirs(out, exist_ok=True)
    for name, kind in [("polygon", shapefile.POLYGON), ("polygonz", shapefile.POLYGONZ), ("polygonm", shapefile.POLYGONM)]:
        base = os.path.join(out, name)
        write(base, kind)
        with open(base + ".json", "w") as f:
            json.dump({"pyshp": shapefile.__version__, "shapes": describe(base + ".shp")}, f, indent=1)
            f.write("\n")
        print(f"wrote {base}.shp/.shx/.dbf/.json")


if __name__ == "__main__":
    main()
