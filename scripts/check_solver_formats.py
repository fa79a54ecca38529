"""Reads the solver files of a `unamalla mesh` output directory with the formats' own tools and
prints one JSON object of what each found. A tool that is not installed gives
{"skipped": "<why>"} for its entry; the Rust tests (crates/unamalla-cli/tests/solver_formats.rs)
compare the findings with the mesh.

    python3 scripts/check_solver_formats.py OUT [--only msh,su2,openfoam,cgns]

* msh:      Gmsh's Python API (PyPI gmsh): surfaces, physical curves with their line-element
            counts, physical surfaces.
* su2:      meshio (PyPI meshio): quads, boundary lines, markers (meshio turns SU2's string
            tags into numbers and names them in a warning, which is parsed).
* openfoam: OpenFOAM's checkMesh (Debian openfoam) on OUT/openfoam: the "Failed N mesh
            checks" / "Mesh OK" verdict and the patch table.
* cgns:     cgnscheck (Debian cgns-convert) on OUT/mesh.cgns (warnings/errors), and VTK's
            vtkCGNSReader (PyPI vtk) as a second reader: zones and cells.
"""
import io, json, os, re, shutil, subprocess, sys, contextlib

out = sys.argv[1]
only = None
if "--only" in sys.argv:
    only = set(sys.argv[sys.argv.index("--only") + 1].split(","))
res = {}

def want(k):
    return only is None or k in only

if want("msh"):
    try:
        import gmsh
        gmsh.initialize(["-v", "0"]) if False else gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(os.path.join(out, "mesh.msh"))
        curves = {}
        surfaces = {}
        for dim, tag in gmsh.model.getPhysicalGroups():
            name = gmsh.model.getPhysicalName(dim, tag)
            n = 0
            for e in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                types, tags, _ = gmsh.model.mesh.getElements(dim, e)
                n += sum(len(t) for t in tags)
            (curves if dim == 1 else surfaces)[name] = n
        res["msh"] = {"surfaces": len(gmsh.model.getEntities(2)), "physical_curves": curves,
                      "physical_surfaces": surfaces}
        gmsh.finalize()
    except ImportError:
        res["msh"] = {"skipped": "Python package gmsh not installed"}

if want("su2"):
    try:
        import meshio
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            import warnings
            with warnings.catch_warnings(record=True) as ws:
                warnings.simplefilter("always")
                m = meshio.read(os.path.join(out, "mesh.su2"))
            text = buf.getvalue() + "\n".join(str(w.message) for w in ws)
        # meshio: "Surface tag  coast will be replaced by 1"
        names = {}
        for name, k in re.findall(r"tag\s+(\S+) will be replaced by (\d+)", text):
            names[int(k)] = name
        cells = {c.type: len(c.data) for c in m.cells}
        markers = {}
        tags = m.cell_data.get("su2:tag", [])
        for block, t in zip(m.cells, tags):
            if block.type == "line":
                for v in t:
                    key = names.get(int(v), str(int(v)))
                    markers[key] = markers.get(key, 0) + 1
        res["su2"] = {"points": len(m.points), "cells": cells, "markers": markers}
    except ImportError:
        res["su2"] = {"skipped": "Python package meshio not installed"}

if want("openfoam"):
    exe = shutil.which("checkMesh")
    if exe is None:
        res["openfoam"] = {"skipped": "checkMesh not found (Debian package openfoam)"}
    else:
        env_script = "/usr/share/openfoam/etc/bashrc"
        cmd = f"checkMesh -case '{os.path.join(out, 'openfoam')}'"
        if os.path.exists(env_script):
            cmd = f". {env_script} >/dev/null 2>&1; " + cmd
        p = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True)
        log = p.stdout + p.stderr
        failed = re.search(r"Failed (\d+) mesh checks", log)
        patches = dict((a, int(b)) for a, b in re.findall(r"^\s{4}(\S+)\s+(\d+)\s+\d+\s+ok", log, re.M))
        cells = re.search(r"cells:\s+(\d+)", log)
        res["openfoam"] = {"mesh_ok": "Mesh OK." in log, "failed_checks": int(failed.group(1)) if failed else 0,
                           "patches": patches, "cells": int(cells.group(1)) if cells else None,
                           "fatal": "FATAL" in log,
                           "problems": [l.strip() for l in log.splitlines() if l.strip().startswith("***")]}

if want("cgns"):
    path = os.path.join(out, "mesh.cgns")
    exe = shutil.which("cgnscheck")
    if not os.path.exists(path):
        res["cgns"] = {"skipped": "no mesh.cgns (build with --features cgns)"}
    elif exe is None:
        res["cgns"] = {"skipped": "cgnscheck not found (Debian package cgns-convert)"}
    else:
        p = subprocess.run([exe, "-v", path], capture_output=True, text=True)
        log = p.stdout + p.stderr
        errors = [l.strip() for l in log.splitlines() if "ERROR" in l]
        warnings_ = [l.strip() for l in log.splitlines() if "WARNING" in l]
        zones = len(re.findall(r"^\s*checking zone", log, re.M | re.I))
        conns = len(re.findall(r"checking 1to1 connectivity|GridConnectivity1to1", log, re.I))
        entry = {"cgnscheck_exit": p.returncode, "errors": errors, "warnings": warnings_,
                 "zones_checked": zones, "log_tail": log.splitlines()[-3:]}
        try:
            import vtk
            r = vtk.vtkCGNSReader()
            r.SetFileName(path)
            r.EnableAllBases()
            r.Update()
            mb = r.GetOutput()
            it = mb.NewIterator()
            it.InitTraversal()
            nblocks, ncells = 0, 0
            while not it.IsDoneWithTraversal():
                ds = it.GetCurrentDataObject()
                if ds is not None and ds.IsA("vtkDataSet") and ds.GetNumberOfCells() > 0 and ds.GetClassName() == "vtkStructuredGrid":
                    nblocks += 1
                    ncells += ds.GetNumberOfCells()
                it.GoToNextItem()
            entry["vtk"] = {"structured_zones": nblocks, "cells": ncells}
        except ImportError:
            entry["vtk"] = {"skipped": "Python package vtk not installed"}
        res["cgns"] = entry

print(json.dumps(res, indent=1, sort_keys=True))
