#!/usr/bin/env bash
# Step 2 of 3, on the GPU machine (CUDA, an NVIDIA driver, no Debian libraries), inside the folder
# prepare.sh wrote (it carries this script):   bash run.sh OUT_DIR
# Writes OUT_DIR/results.tgz: cuda/NAME.raw (seed 001's kernel on each frame: the harness, 2-int header,
# RGBA float32; its loops' guard marks a ray that cannot end as (-1, outAbs, inAbs, -1)), glsl/NAME.raw
# (seed 002's program through EGL's device platform, 3-int header), fetches/*.csv (dump_fetches.cu),
# env.txt and the logs. Each program has a time limit (TIMEOUT, default 120 s per frame).
set -uo pipefail
OUT=$(mkdir -p "${1:?usage: run.sh OUT_DIR}" && cd "$1" && pwd)
cd "$(dirname "$0")"
R=$(mktemp -d); mkdir -p "$R/cuda" "$R/glsl" "$R/fetches"
T=${TIMEOUT:-120}
{ date; nvidia-smi -L; nvcc --version | tail -1; nproc; } > "$R/env.txt" 2>&1; cat "$R/env.txt"
ARCH=${CUDA_ARCH:-native}
# seed 001
if nvcc -O3 -std=c++17 -arch="$ARCH" -o "$R/seed001" cuda_curvilinear.cu seed001_harness.cpp -I. 2> "$R/nvcc.log"; then
    for f in frames/*.frame; do n=$(basename "$f" .frame)
        timeout "$T" "$R/seed001" "$f" "$R/cuda/$n.raw"; echo "cuda $n rc=$?"
    done > "$R/cuda.log" 2>&1
else echo "nvcc failed: $R/nvcc.log" | tee -a "$R/cuda.log"; fi
# the texture unit's fetches
if [ -f dump_fetches.cu ] && nvcc -O2 -arch="$ARCH" -o "$R/dump_fetches" dump_fetches.cu 2>> "$R/nvcc.log"; then
    timeout "$T" "$R/dump_fetches" "$R/fetches" > "$R/fetches.log" 2>&1; echo "fetches rc=$?" >> "$R/fetches.log"
fi
# seed 002 through EGL's device platform; EGL needs libglvnd (Debian's libegl1, libopengl0 ... unpacked in
# GL_DEBS, a folder of .deb files, when the machine lacks them)
if [ -n "${GL_DEBS:-}" ]; then for d in "$GL_DEBS"/*.deb; do dpkg -x "$d" /; done; ldconfig 2>/dev/null; fi
tar xJf bundle.tar.xz
export LD_LIBRARY_PATH=$PWD/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
for s in scenes/glsl/*.json; do n=$(basename "$s" .json)
    timeout "$T" bin/glsl_raycaster "$s" "$R/glsl/$n.raw" --egl-device; echo "glsl $n rc=$?"
done > "$R/glsl.log" 2>&1
grep -c "rc=0" "$R/cuda.log" "$R/glsl.log"; grep -h "rc=[1-9]" "$R/cuda.log" "$R/glsl.log" | head
tar czf "$OUT/results.tgz" -C "$R" .
ls -la "$OUT"
