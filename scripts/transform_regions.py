#!/usr/bin/env python3
"""Write transformed copies of GeoJSON regions, to test that meshing does not depend on units,
orientation or offsets (docs/results.md, "Units, rotation and stretch").

usage: python3 scripts/transform_regions.py SRC_DIR OUT_DIR MODE

MODE:
  p2small  every coordinate times 2^-14 (exact in floating point)
  p2big    every coordinate times 2^20 (exact in floating point)
  tiny     every coordinate times 1e-4
  rot      rotated by 37 degrees about the origin
  utm      metres with false easting/northing: (500000 + 111320 cos(phi0) x, 4000000 + 110540 y),
           phi0 the mean y of the file (a stretch by 1/cos(phi0) in y, and offsets of 1e6-1e8)

Mesh the copies with `--crs planar` (their coordinates are no longer longitude/latitude):
  OUT=/tmp/ev_MODE ../shared/tools/eval_regions.sh OUT_DIR --cells 20000 --crs planar
"""
import glob
import json
import math
import os
import sys

MODES = ("p2small", "p2big", "tiny", "rot", "utm")


def transform(c, mode, lat0):
    x, y = c[0], c[1]
    if mode == "p2small":
        return [x * 2.0**-14, y * 2.0**-14]
    if mode == "p2big":
        return [x * 2.0**20, y * 2.0**20]
    if mode == "tiny":
        return [x * 1e-4, y * 1e-4]
    if mode == "rot":
        a = math.radians(37)
        return [x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)]
    # utm
    return [500000.0 + x * 111320.0 * math.cos(math.radians(lat0)), 4000000.0 + y * 110540.0]


def walk(g, f):
    if isinstance(g[0], (int, float)):
        return f(g)
    return [walk(h, f) for h in g]


def ys_of(g, out):
    if isinstance(g[0], (int, float)):
        out.append(g[1])
        return
    for h in g:
        ys_of(h, out)


def main():
    if len(sys.argv) != 4 or sys.argv[3] not in MODES:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    src, out, mode = sys.argv[1:4]
    os.makedirs(out, exist_ok=True)
    files = sorted(glob.glob(os.path.join(src, "*.geojson")))
    if not files:
        print(f"no .geojson file in {src}", file=sys.stderr)
        sys.exit(2)
    for f in files:
        d = json.load(open(f))
        feats = d["features"] if d.get("type") == "FeatureCollection" else [d]
        geoms = [ft["geometry"] if "geometry" in ft else ft for ft in feats]
        ys = []
        for g in geoms:
            ys_of(g["coordinates"], ys)
        lat0 = sum(ys) / len(ys)
        for g in geoms:
            g["coordinates"] = walk(g["coordinates"], lambda c: transform(c, mode, lat0))
        d.pop("crs", None)
        with open(os.path.join(out, os.path.basename(f)), "w") as w:
            json.dump(d, w)
    print(f"{len(files)} regions written to {out}")


if __name__ == "__main__":
    main()
