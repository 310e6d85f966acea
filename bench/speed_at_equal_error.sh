#!/bin/sh
# Speed at equal error (issue 19): volref's reference and fast profiles at several steps against VTK's
# vtkFixedPointVolumeRayCastMapper on the benchmark frame, interleaved, at 1 and 2 threads; rewrites the
# "## Speed at equal error" section of docs/performance.md (bench/vtk/equal_error.py says
# what it measures and how).
#
#   bench/speed_at_equal_error.sh            # about 6 min on 2 cores
#
# Installs what is missing and builds volref's CLI and bench/make_ml_volume (bench/vtk/prepare.sh).
# Settings (environment): EQ_REPS (3) rounds, EQ_FRAMES (3) timed frames per run, EQ_THREADS ("1 2"),
# EQ_REFERENCE_STEPS ("0.5 1 2 3 4"), EQ_FAST_STEPS ("1 2 2.25 2.3 2.4 2.5 3 4 6"), EQ_PRE_STEPS ("2 3 4 6") and EQ_PRE_TABLE (256) the pre-integrated fast profile's, EQ_REF_STEP (0.125) the fine
# reference's step in voxels, EQ_OUT (build/equal-error) where the images and raw results go,
# EQ_NO_DOC=1 leaves docs/performance.md alone (the section is still written to $EQ_OUT/section.md).
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
build=${VOLREF_BUILD:-$root/build}
out=${EQ_OUT:-$build/equal-error}
export VOLREF_BUILD="$build"
log() { printf '%s [%s] %s\n' "$(date +%H:%M:%S)" "equal-error" "$*" >&2; }

. "$root/bench/vtk/prepare.sh"
prepare_vtk_bench volref_cli make_ml_volume

doc="--doc $root/docs/performance.md"
[ "${EQ_NO_DOC:-0}" = 1 ] && doc=""
mkdir -p "$out"
# shellcheck disable=SC2086
xvfb-run -a -s "-screen 0 1024x768x24" /usr/bin/python3 "$root/bench/vtk/equal_error.py" "$out" $doc \
    --reps "${EQ_REPS:-3}" --frames "${EQ_FRAMES:-3}" --threads "${EQ_THREADS:-1 2}" \
    --reference-steps "${EQ_REFERENCE_STEPS:-0.5 1 2 3 4}" --fast-steps "${EQ_FAST_STEPS:-1 2 2.25 2.3 2.4 2.5 3 4 6}" --pre-steps "${EQ_PRE_STEPS:-2 3 4 6}" --pre-table "${EQ_PRE_TABLE:-256}" \
    --ref-step "${EQ_REF_STEP:-0.125}"
