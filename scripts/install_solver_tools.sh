#!/usr/bin/env bash
# Installs the solver and GIS tools the cross-check tests use. Every test that needs
# one of them prints "skipped: ..." and passes when it is absent, so this script is optional.
#
#   * OpenFOAM's checkMesh            Debian package `openfoam`
#   * cgnscheck (CGNS library tools)   Debian package `cgns-convert`; `libcgns-dev` for `--features cgns`
#   * headless Chromium                Debian package `chromium` (report.html render test)
#   * Gmsh Python API, meshio, VTK     PyPI `gmsh`, `meshio`, `vtk`
#
# Usage: bash scripts/install_solver_tools.sh   (as root; a few minutes, ~1.5 GB)
set -uo pipefail
status=0
if command -v apt-get >/dev/null 2>&1; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq || status=1
  apt-get install -y -qq --no-install-recommends openfoam cgns-convert libcgns-dev chromium \
    || { echo "warning: apt-get install failed; the OpenFOAM/CGNS/Chromium checks will be skipped"; status=1; }
else
  echo "warning: no apt-get; install openfoam, cgns-convert and chromium by hand"
  status=1
fi
if command -v python3 >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check meshio gmsh vtk \
    || { echo "warning: pip install meshio/gmsh/vtk failed"; status=1; }
fi
exit $status
