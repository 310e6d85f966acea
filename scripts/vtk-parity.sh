#!/bin/sh
# VTK parity: volref's vtk-gpu profile against VTK 9.1's vtkGPUVolumeRayCastMapper (Debian's
# python3-vtk9 on Mesa llvmpipe under Xvfb) on small composite (unshaded and shaded), MIP, MinIP and
# average scenes, and its vtk-cpu profile against vtkFixedPointVolumeRayCastMapper on the same
# composite, shaded, MIP and MinIP scenes, each within 8-bit quantisation (plus the measured
# tolerance bench/vtk/parity.py states per case); the reference profile's difference is reported
# with `volref compare --fit`.
#
#   scripts/vtk-parity.sh VOLREF [OUT_DIR] [CASE ...]
#
# VOLREF: the volref executable; OUT_DIR (default: a temporary folder, removed afterwards) keeps the
# scenes and images. Exit 0: every case matched; 1: a case did not; 2: usage or a failed render;
# 77: python3-vtk9 or xvfb-run is missing (ctest reports the test as skipped). Installed by
# scripts/install-deps.sh: python3-vtk9 python3-numpy xvfb xauth. docs/gpu-checking.md has the
# measured differences.
set -eu
if [ $# -lt 1 ]; then echo "usage: $0 VOLREF [OUT_DIR] [CASE ...]" >&2; exit 2; fi
volref=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
shift
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
if ! command -v xvfb-run >/dev/null 2>&1 || ! /usr/bin/python3 -c "import vtkmodules, numpy" 2>/dev/null; then
    echo "vtk-parity.sh: skipped: needs xvfb-run and Debian's python3-vtk9 and python3-numpy (scripts/install-deps.sh)" >&2
    exit 77
fi
if [ $# -ge 1 ]; then
    out=$1
    shift
    mkdir -p "$out"
else
    out=$(mktemp -d)
    trap 'rm -rf "$out"' EXIT
fi
# VTK's GPU mapper runs on Mesa's software OpenGL: one thread keeps the test's load small.
LP_NUM_THREADS=${LP_NUM_THREADS:-1} xvfb-run -a -s "-screen 0 640x480x24" \
    /usr/bin/python3 "$root/bench/vtk/parity.py" "$volref" "$out" "$@"
