#!/usr/bin/env bash
# One slicing test (tests/gpu/slicing/CMakeLists.txt): renders SCENE with gl_slicer on llvmpipe and with
# `volref render` (the scene's own render.profile, placement "slices") and compares them at the bounds
# derive_tolerance.py derives from the arithmetic:
#   SMALL  the first-order bound: every pixel where no rounding event (a fragment's code or table index
#          decided by the float32 / double difference, one of llvmpipe's rounded-down products) happened;
#   M      the most pixels over SMALL that events explain (exceeded with chance <= 1e-3);
#   BIG    SMALL plus K events, the most on any one pixel (exceeded with chance <= 1e-2).
# The images agree when no pixel is over BIG and at most M pixels are over SMALL (two `volref compare`
# runs: --tolerance BIG must exit 0; --tolerance SMALL --json counts the pixels over).
# Usage: run_case.sh GL_SLICER VOLREF SCENE.json OUTDIR [VARIANT]
# With VARIANT one of the two renders another convention and the test passes only when the images do not
# agree: the comparison is tight enough to see it. VARIANT: SLICER_* (gl_slicer --define: SLICER_CORRECTED,
# SLICER_HALF, SLICER_FLOAT_FB, SLICER_LINEAR_TABLE, SLICER_DATA_WINDOW, SLICER_NO_NEAR_FAR); LLVMPIPE_DEFAULT
# (gl_slicer as it is, GALLIVM_PERF unset: llvmpipe's default 8-bit filter, 8.8 fixed point, on a scene whose
# texture_filter is "exact"); LLVMPIPE_NO_AOS (gl_slicer with GALLIVM_PERF=no_aos_sampling: llvmpipe's exact
# filter on a scene whose texture_filter is "fixed8"); VOLREF_EXACT_PRODUCTS (volref with
# --set render.profile.blend_products=exact on a scene whose products are llvmpipe's).
# Exit 0 = as expected; anything else fails (no GL context is a failure, never a skip).
set -euo pipefail
slicer=$1 volref=$2 scene=$3 out=$4 variant=${5:-}
name=$(basename "$scene" .json)${variant:+-$variant}
here=$(cd "$(dirname "$0")" && pwd)
read -r small count big < <(/usr/bin/python3 "$here/derive_tolerance.py" "$scene")
echo "run_case.sh: $name: first-order tolerance $small, at most $count pixels past it, none past $big (derive_tolerance.py)"
mkdir -p "$out"
volref_set=()
case "$variant" in
  LLVMPIPE_DEFAULT) env -u GALLIVM_PERF "$slicer" "$scene" "$out/$name-gl.exr" --require-renderer llvmpipe ;;
  LLVMPIPE_NO_AOS) env GALLIVM_PERF=no_aos_sampling "$slicer" "$scene" "$out/$name-gl.exr" --require-renderer llvmpipe ;;
  VOLREF_EXACT_PRODUCTS)
    "$slicer" "$scene" "$out/$name-gl.exr" --require-renderer llvmpipe
    volref_set=(--set render.profile.blend_products=exact) ;;
  "" | SLICER_*) "$slicer" "$scene" "$out/$name-gl.exr" --require-renderer llvmpipe ${variant:+--define "$variant"} ;;
  *) echo "run_case.sh: unknown variant $variant" >&2; exit 2 ;;
esac
"$volref" render "$scene" -o "$out/$name-volref.exr" "${volref_set[@]}"
set +e
"$volref" compare "$out/$name-gl.exr" "$out/$name-volref.exr" --tolerance "$big" --heatmap "$out/$name-diff.png"
rc_big=$?
"$volref" compare "$out/$name-gl.exr" "$out/$name-volref.exr" --tolerance "$small" --json > "$out/$name-compare.json"
rc_small=$?
set -e
if [ $rc_big -gt 1 ] || [ $rc_small -gt 1 ]; then echo "run_case.sh: volref compare failed" >&2; exit 2; fi
over=$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["overall"]["pixels_over"])' "$out/$name-compare.json")
echo "run_case.sh: $name: $over pixels past $small (at most $count), $([ $rc_big -eq 0 ] && echo none || echo some) past $big"
agree=0
[ $rc_big -eq 0 ] && [ "$over" -le "$count" ] && agree=1
if [ -z "$variant" ]; then
  [ $agree -eq 1 ] && exit 0
  echo "run_case.sh: $name: gl_slicer and volref disagree past the derived bounds" >&2
  exit 1
fi
[ $agree -eq 0 ] && { echo "run_case.sh: with $variant the images differ past the bounds, as they should"; exit 0; }
echo "run_case.sh: with $variant the comparison still agrees: it cannot see the convention" >&2
exit 1
