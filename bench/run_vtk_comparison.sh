#!/bin/sh
# volref beside VTK: renders the same 256^3 Marschner-Lobb scene (four cases: composite, shaded,
# MIP, dense) with volref and with VTK's vtkFixedPointVolumeRayCastMapper and
# vtkGPUVolumeRayCastMapper (Mesa llvmpipe here: no GPU), interleaved, at 1 and 2 threads, and
# rewrites the "## volref beside VTK" section of docs/performance.md with frame rates, samples per
# second and each image's error against volref's most accurate reference.
#
#   bench/run_vtk_comparison.sh            # about 10 min on 2 cores (see docs/performance.md)
#
# It installs what is missing (python3-vtk9, python3-numpy, xvfb, xauth, and openimageio-tools for
# reading images; apt-get, with sudo when not root), builds volref's CLI if needed (Release, in
# build/ or $VOLREF_BUILD), runs bench/vtk/driver.sh under xvfb-run, then bench/vtk/report.py.
# Raw results go to $VTK_CMP_OUT (default build/vtk-comparison). Settings for a shorter run are
# listed in bench/vtk/driver.sh (VTK_CMP_REPS, VTK_CMP_FRAMES, VTK_CMP_THREADS, VTK_CMP_CASES,
# VTK_CMP_REF_STEP); VTK_CMP_NO_DOC=1 leaves docs/performance.md alone (the section is still
# written to $VTK_CMP_OUT/section.md).
set -eu

start=$(date +%s.%N)
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
build=${VOLREF_BUILD:-$root/build}
out=${VTK_CMP_OUT:-$build/vtk-comparison}
export VOLREF_BUILD="$build"

log() { printf '%s [%s] %s\n' "$(date +%H:%M:%S)" "vtk-comparison" "$*" >&2; }

# 1-2. Packages (Debian 12) and volref's CLI (Release): bench/vtk/prepare.sh.
. "$root/bench/vtk/prepare.sh"
prepare_vtk_bench volref_cli

# 3. The runs, under one X server for all VTK processes.
log "running bench/vtk/driver.sh (results in $out)"
xvfb-run -a -s "-screen 0 1024x768x24" "$root/bench/vtk/driver.sh" "$out"

# 4. The report.
case "$out" in "$root"/*) label=${out#"$root"/} ;; *) label=$out ;; esac
doc="--doc $root/docs/performance.md"
[ "${VTK_CMP_NO_DOC:-0}" = 1 ] && doc=""
# shellcheck disable=SC2086
/usr/bin/python3 "$root/bench/vtk/report.py" "$out" $doc --command "bench/run_vtk_comparison.sh" \
    --start "$start" --out-label "$label"
log "done in $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.0f", b - a }') s"
