#!/usr/bin/env bash
# One glsl test (tests/gpu/glsl/CMakeLists.txt): renders SCENE with seed 002's GLSL program on llvmpipe and
# with volref's glsl-basic profile and compares them at the tolerance derive_tolerance.py derives from the
# arithmetic (docs/gpu-checking.md).
# Usage: run_case.sh GLSL_RAYCASTER VOLREF SCENE.json OUTDIR [VARIANT]
# With VARIANT (a macro raycast.frag knows: SEED_NO_CUTOFF, SEED_NO_TERMINATION, SEED_TF_COLOUR) the
# program runs without that quirk and the test passes only when `volref compare` finds the images
# different (exit 1): the comparison is tight enough to see the quirk.
# Exit 0 = as expected; anything else fails (no GL context is a failure, never a skip).
set -euo pipefail
raycaster=$1 volref=$2 scene=$3 out=$4 variant=${5:-}
name=$(basename "$scene" .json)${variant:+-$variant}
here=$(cd "$(dirname "$0")" && pwd)
tol=$(/usr/bin/python3 "$here/derive_tolerance.py" "$scene")
echo "run_case.sh: $name: tolerance $tol (derive_tolerance.py)"
mkdir -p "$out"
"$raycaster" "$scene" "$out/$name-glsl.exr" --require-renderer llvmpipe ${variant:+--define "$variant"}
"$volref" render "$scene" -o "$out/$name-glsl-basic.exr" --set render.profile=glsl-basic
set +e
"$volref" compare "$out/$name-glsl.exr" "$out/$name-glsl-basic.exr" --tolerance "$tol" --heatmap "$out/$name-diff.png"
rc=$?
set -e
if [ -z "$variant" ]; then exit $rc; fi
[ $rc -eq 1 ] && { echo "run_case.sh: without $variant the images differ past the tolerance, as they should"; exit 0; }
echo "run_case.sh: without $variant the comparison still passed (rc $rc): it cannot see the quirk" >&2
exit 1
