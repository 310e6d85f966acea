#!/usr/bin/env bash
# The README's first command: install what is missing, build, render the default reference scene,
# and print the image's path.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/fetch-reference-data.sh   # the real reference volumes (Debian packages' data, git-ignored)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
build/cli/volref render reference_scenes/default.json -o build/default.png
