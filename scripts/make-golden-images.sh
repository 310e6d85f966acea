#!/usr/bin/env bash
# Regenerates the golden images of the real reference scenes, tests/golden/NAME.exr: each
# reference_scenes/NAME.json on real data rendered at 48 x 48 with `volref render` (the scene's own step).
# tests/unit/test_real_data.cpp compares its own renders with them (tolerance stated there). Run this
# only after a change that is meant to change these images, and say why in the commit.
#
# Usage: scripts/make-golden-images.sh [VOLREF]   (default: build/cli/volref, built if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
volref=${1:-build/cli/volref}
if [[ ! -x "$volref" ]]; then
    echo "make-golden-images: $volref is missing; building" >&2
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
    cmake --build build
fi
scripts/fetch-reference-data.sh
mkdir -p tests/golden
for name in mri-head ct-heart mri-brain-volpack; do
    echo "make-golden-images: reference_scenes/$name.json -> tests/golden/$name.exr" >&2
    "$volref" render "reference_scenes/$name.json" -o "tests/golden/$name.exr" \
        --set image.width=48 --set image.height=48
done
