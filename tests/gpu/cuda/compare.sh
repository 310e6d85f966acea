#!/usr/bin/env bash
# Seed 001's CUDA program (and seed 002's GLSL program) on a real GPU against volref's profiles (issues 17,
# 27, 28). No test needs a GPU: the programs' images recorded on one are fixtures (tests/gpu/h100) that ctest
# compares without one (ctest h100_fixtures). To record new ones when a GPU machine is lent
# (it has CUDA and a driver but none of Debian's libraries, and carries at most 64 MiB: inputs, not
# libraries), three steps (tests/gpu/device/README.md):
#   tests/gpu/cuda/compare.sh prepare [BUILD_DIR [CARRY_DIR]]           here: frames, sources, the GLSL bundle
#   bash CARRY_DIR/run.sh OUT_DIR                                        on the GPU machine, as it is
#   tests/gpu/cuda/compare.sh collect RESULTS.tgz CARRY_DIR FIXTURE_DIR  here: EXRs beside their scenes, and
#                                                                        compare_fixtures.py --check on them
# The comparison's rule (docs/gpu-checking.md): each profile as its program runs (cuda-curvilinear's float32
# kernel, glsl-basic; texture_unit "h100"), every pixel within the error channel (texture_band) plus 2e-4
# (seed 002: plus derive_tolerance.py's bound), and seed 001's `fault` pixels exactly the rays the
# program's guard marked (-1, outAbs, inAbs, -1).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
case "${1:-}" in
    prepare) shift; exec "$here/../device/prepare.sh" "$@" ;;
    collect) shift; exec "$here/../device/collect.sh" "$@" ;;
    *) sed -n '2,16p' "$0" >&2; exit 2 ;;
esac
