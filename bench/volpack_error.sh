#!/bin/sh
# VolPack's error, measured (issue 55, item 4): VolPack 1.0b3's images of bench/volpack/*.json against
# volref's reference of the continuous scene each one discretises (step 1/8 voxel; 1/16 and the adaptive
# integrator as its convergence check), the error's causes, and the times of VolPack, volref's volpack
# profile, the reference and the fast profile at VolPack's RMSE, interleaved at 1 and 2 threads; rewrites
# the "## VolPack: its error against the reference, and its speed" section of
# docs/performance.md (bench/volpack/volpack_error.py says what it measures and how).
#
#   bench/volpack_error.sh            # about 25 min on 2 cores (the adaptive renders take half)
#
# Needs Debian's libvolpack1-dev (scripts/install-deps.sh), reference_scenes/data/real/brainsmall.den
# (scripts/fetch-reference-data.sh) and /usr/bin/python3 with numpy and OpenImageIO; builds volref_cli
# and volpack_render if missing (Release, build/ or $VOLREF_BUILD). The 8-bit Marschner-Lobb 256^3 volume is
# written to build/volpack-bench/marschner-lobb-256.nrrd (bench/volpack/make_ml_u8.py) if missing: the
# scenes name that path. Settings (environment): VOLPACK_ERR_REPS (3) timing rounds, VOLPACK_ERR_FRAMES (5)
# frames per timed run, VOLPACK_ERR_THREADS ("1 2"), VOLPACK_ERR_TOLERANCE (1e-4) the adaptive integrator's
# render.tolerance, VOLPACK_ERR_FAST_STEPS ("0.25 0.5 0.75 1 1.5 2 3 4 6 8 12 16"), VOLPACK_ERR_SCENES
# (all), VOLPACK_ERR_OUT (build/volpack-error) where the images and results.json go, VOLPACK_ERR_NO_DOC=1
# leaves docs/performance.md alone (the section is still written to $VOLPACK_ERR_OUT/section.md).
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
build=${VOLREF_BUILD:-$root/build}
out=${VOLPACK_ERR_OUT:-$build/volpack-error}
export VOLREF_BUILD="$build"

if [ ! -x "$build/cli/volref" ] || [ ! -x "$build/tests/volpack/volpack_render" ]; then
    [ -f "$build/CMakeCache.txt" ] || cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release
    cmake --build "$build" --target volref_cli volpack_render
fi

doc="--doc $root/docs/performance.md"
[ "${VOLPACK_ERR_NO_DOC:-0}" = 1 ] && doc=""
scenes=${VOLPACK_ERR_SCENES:-}
case "$out" in "$root"/*) label=${out#"$root"/} ;; *) label=$out ;; esac
mkdir -p "$out"
# shellcheck disable=SC2086
/usr/bin/python3 "$root/bench/volpack/volpack_error.py" "$out" $doc --out-label "$label" \
    --reps "${VOLPACK_ERR_REPS:-3}" --frames "${VOLPACK_ERR_FRAMES:-5}" --threads "${VOLPACK_ERR_THREADS:-1 2}" \
    --tolerance "${VOLPACK_ERR_TOLERANCE:-1e-4}" \
    --fast-steps "${VOLPACK_ERR_FAST_STEPS:-0.25 0.5 0.75 1 1.5 2 3 4 6 8 12 16}" \
    ${scenes:+--scenes "$scenes"} --command "bench/volpack_error.sh"
