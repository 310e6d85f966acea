#!/usr/bin/env bash
# Seed 001's CUDA program (cuda_curvilinear) against volref's cuda-curvilinear profile (issue 17, part 2).
# Needs an NVIDIA GPU: not a ctest test (no test may need a GPU). Run it by hand where one exists:
#   tests/gpu/cuda/compare.sh [BUILD_DIR [OUT_DIR]]      (BUILD_DIR default: build)
# For each scene under tests/gpu/cuda/scenes/: the program's image (OUT/NAME-cuda.exr), volref's with the
# profile's texture band (OUT/NAME-profile.exr, render.profile_options.texture_band true: the error
# channel bounds what any texture unit within the 1/256-weight model can do) and, for reference, with
# the H100 texture unit (OUT/NAME-h100.exr); `volref compare --tolerance-from-error --tolerance T`
# must pass. Both volref renders read the data as the program does (texture_format "unorm16": v / 65535).
# T (default 2e-3, VOLREF_CUDA_TOLERANCE) stands for what the band does not hold: float32 positions and
# the seed's s -= step accumulation, float32 barycentric intersections with the same triangles, the
# table in float32; it is a first estimate, not yet checked
# against a GPU (docs/gpu-checking.md). One line per scene and a summary; exit 0 when all pass, 1 when
# some differ past the tolerance, 2 when something could not run (no GPU: the program exits 3).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
build=${1:-$root/build}
out=${2:-$build/tests/gpu/cuda/out}
tol=${VOLREF_CUDA_TOLERANCE:-2e-3}
program=$build/tests/gpu/cuda/cuda_curvilinear
volref=$build/cli/volref
[ -x "$program" ] || { echo "compare.sh: no $program (configure with a CUDA compiler)" >&2; exit 2; }
[ -x "$volref" ] || { echo "compare.sh: no $volref" >&2; exit 2; }
mkdir -p "$out"
status=0
printf '%-22s %-8s %s\n' scene result "volref compare (max abs per channel; tolerance $tol + error channel)"
for scene in "$here"/scenes/*.json; do
    name=$(basename "$scene" .json)
    if ! "$program" "$scene" "$out/$name-cuda.exr"; then
        echo "compare.sh: $name: the CUDA program failed (no GPU?)" >&2
        exit 2
    fi
    "$volref" render "$scene" -o "$out/$name-profile.exr" --set render.profile=cuda-curvilinear \
        --set render.profile_options.texture_format=unorm16 --set render.profile_options.texture_band=true > /dev/null || exit 2
    "$volref" render "$scene" -o "$out/$name-h100.exr" --set render.profile=cuda-curvilinear \
        --set render.profile_options.texture_format=unorm16 --set render.profile_options.texture_unit=h100 > /dev/null || exit 2
    "$volref" compare "$out/$name-cuda.exr" "$out/$name-profile.exr" --tolerance-from-error --tolerance "$tol" \
        --heatmap "$out/$name-diff.png" > "$out/$name-compare.txt" 2>&1
    rc=$?
    "$volref" compare "$out/$name-cuda.exr" "$out/$name-h100.exr" > "$out/$name-compare-h100.txt" 2>&1
    case $rc in
        0) result=pass ;;
        1) result=DIFFERS; [ $status -eq 0 ] && status=1 ;;
        *) result=ERROR; status=2 ;;
    esac
    printf '%-22s %-8s %s\n' "$name" "$result" "$(grep -i 'max' "$out/$name-compare.txt" | head -1)"
done
echo "compare.sh: details in $out/*-compare.txt (against the H100 texture unit: *-compare-h100.txt)"
exit $status
