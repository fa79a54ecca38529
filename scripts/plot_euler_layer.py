#!/usr/bin/env python3
"""Pressure on the middle layer x ≈ 0 of `euler_blast` outputs (cells i = w/2 of the radial grid,
drawn by their i− face in the (y, z) plane), one panel per file.

    python3 scripts/plot_euler_layer.py OUT.png A.vtu[:title] B.vtu[:title] ...

Needs numpy, meshio, matplotlib."""
import sys
import numpy as np, meshio
import matplotlib; matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import PolyCollection

out, files = sys.argv[1], sys.argv[2:]
fig, axes = plt.subplots(1, len(files), figsize=(5 * len(files), 5.4))
axes = np.atleast_1d(axes)
for ax, spec in zip(axes, files):
    path, _, title = spec.partition(":")
    m = meshio.read(path)
    hexes = m.cells_dict["hexahedron"]; p = m.cell_data_dict["pressure"]["hexahedron"]
    w = round(len(hexes) ** (1 / 3))
    i = w // 2
    sel = [i + w * (j + w * k) for k in range(w) for j in range(w)]
    polys = m.points[hexes[sel]][:, [0, 3, 7, 4]][:, :, 1:]   # i- face, (y, z)
    pc = PolyCollection(polys, array=p[sel], cmap="viridis", edgecolors="k", linewidths=0.1)
    ax.add_collection(pc); ax.autoscale(); ax.set_aspect("equal")
    ax.set_xlabel("y"); ax.set_ylabel("z"); ax.set_title(title or path)
    fig.colorbar(pc, ax=ax, shrink=0.8, label="pressure")
fig.tight_layout(); fig.savefig(out, dpi=90)
