#!/usr/bin/env bash
# Step 1 of 3, on this (CPU) machine: everything a GPU machine needs to record new fixtures, in one folder
# (issue 28). The GPU machine has CUDA and a driver but none of Debian's libraries, and what travels is
# capped (64 MiB): carry inputs, not libraries.
#   tests/gpu/device/prepare.sh [BUILD_DIR [CARRY_DIR]]     (defaults: build, build/device-carry)
# CARRY_DIR then holds:
#   frames/NAME.frame   seed 001's frame for each scene (the project's own host, cuda_curvilinear_host.cpp,
#                       linked with dump_frame.cpp instead of the CUDA renderer), scenes/cuda/NAME.json beside
#   cuda_curvilinear.cu, seed001.h, seed001_harness.cpp   the kernel and a main that renders a frame file
#   dump_fetches.cu     the texture unit's ground truth (../shared/gpu), if present
#   bundle.tar.xz       bin/glsl_raycaster (seed 002's program linked against libvolref_core alone, images
#                       written as raw float by raw_writer.cpp) and lib/ (the libraries it needs)
#   raycast.frag, scenes/glsl/NAME.json
#   run.sh              step 2 (tests/gpu/device/run.sh)
# Scenes: tests/gpu/h100/seed001 and seed002 (the fixtures: to re-record them) and tests/gpu/cuda/scenes,
# tests/gpu/glsl/scenes; add more with SCENES_CUDA / SCENES_GLSL (space-separated paths).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
P=$(cd "$here/../../.." && pwd)
B=$(cd "${1:-$P/build}" && pwd)
C=${2:-$B/device-carry}
rm -rf "$C"; mkdir -p "$C/frames" "$C/scenes/cuda" "$C/scenes/glsl" "$C/lib" "$C/bin"
CXX="g++ -O3 -DNDEBUG -ffp-contract=off -std=c++20 -I$P -I$P/tests/gpu/cuda -I/usr/include/nifti"
# 1. seed 001: frames by the project's own host
$CXX -o "$C/.dump_host" "$P/tests/gpu/cuda/cuda_curvilinear_host.cpp" "$here/dump_frame.cpp" \
    -L"$B" -lvolref_tools -lvolref_core -Wl,-rpath,"$B"
for s in "$P"/tests/gpu/h100/seed001/*.json "$P"/tests/gpu/cuda/scenes/*.json ${SCENES_CUDA:-}; do
    n=$(basename "$s" .json)
    [ -f "$C/scenes/cuda/$n.json" ] && n="$n-$(basename "$(dirname "$s")")"
    # a scene that names a data file carries it, rewritten to its own folder
    /usr/bin/python3 - "$s" "$C/scenes/cuda/$n.json" <<'PY'
import json, os, shutil, sys
s = json.load(open(sys.argv[1])); src = s["volume"]["source"]
if "file" in src:
    f = os.path.join(os.path.dirname(os.path.abspath(sys.argv[1])), src["file"])
    shutil.copy(f, os.path.join(os.path.dirname(sys.argv[2]), os.path.basename(f)))
    src["file"] = os.path.basename(f)
json.dump(s, open(sys.argv[2], "w"))
PY
    SEED001_FRAME_OUT="$C/frames/$n.frame" "$C/.dump_host" "$C/scenes/cuda/$n.json" "$C/.frame.exr" > /dev/null
done
rm -f "$C/.dump_host" "$C/.frame.exr"
cp "$P/tests/gpu/cuda/cuda_curvilinear.cu" "$P/tests/gpu/cuda/seed001.h" "$here/seed001_harness.cpp" "$here/run.sh" "$C/"
[ -f "$P/tests/data/h100-fetches/dump_fetches.cu" ] && cp "$P/tests/data/h100-fetches/dump_fetches.cu" "$C/"
# 2. seed 002: the GLSL program against libvolref_core alone, writing raw float images
$CXX -DVOLREF_GLSL_SHADER='"raycast.frag"' -o "$C/bin/glsl_raycaster" "$P/tests/gpu/glsl/glsl_raycaster.cpp" "$here/raw_writer.cpp" \
    -L"$B" -lvolref_core -lOpenGL -lEGL -Wl,-rpath,'$ORIGIN/../lib'
cp "$P/tests/gpu/glsl/raycast.frag" "$C/"
for s in "$P"/tests/gpu/h100/seed002/*.json "$P"/tests/gpu/glsl/scenes/*.json ${SCENES_GLSL:-}; do
    [ -f "$C/scenes/glsl/$(basename "$s")" ] || cp "$s" "$C/scenes/glsl/"  # the fixtures' scenes are the glsl tests'
done
for l in $(LD_LIBRARY_PATH=$B ldd "$C/bin/glsl_raycaster" | awk '/=>/{print $3}' | sort -u | grep -E 'volref|embree|tbb|hwy|tinyobj|nifti|znz'); do
    cp -L "$l" "$C/lib/"
done
(cd "$C" && tar cJf bundle.tar.xz lib bin && rm -rf lib bin)
du -sh "$C"
echo "prepare.sh: carry $C to the GPU machine and run run.sh there (tests/gpu/device/README.md)"
