#!/usr/bin/env bash
# Step 3 of 3, back on this (CPU) machine: the GPU's results as fixtures, then the profiles against them.
#   tests/gpu/device/collect.sh RESULTS.tgz CARRY_DIR FIXTURE_DIR [BUILD_DIR]
# FIXTURE_DIR/seed001/NAME.{json,h100.exr} (and data files) and FIXTURE_DIR/seed002/NAME.{json,h100.exr},
# as tests/gpu/h100 holds them (copy them there, with a note of the machine in its README, to make them
# the CI's fixtures); then compare_fixtures.py --fixtures FIXTURE_DIR --check --markdown (issues 27, 28).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
P=$(cd "$here/../../.." && pwd)
res=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
C=$(cd "$2" && pwd)
F=$(mkdir -p "$3" && cd "$3" && pwd)
B=$(cd "${4:-$P/build}" && pwd)
W=$(mktemp -d); tar xzf "$res" -C "$W"
mkdir -p "$F/seed001" "$F/seed002"
for r in "$W"/cuda/*.raw; do [ -e "$r" ] || continue; n=$(basename "$r" .raw)
    cp "$C/scenes/cuda/$n.json" "$F/seed001/"
    f=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["volume"]["source"].get("file",""))' "$C/scenes/cuda/$n.json")
    [ -n "$f" ] && cp "$C/scenes/cuda/$f" "$F/seed001/"
    /usr/bin/python3 "$here/raw2exr.py" "$r" "$F/seed001/$n.h100.exr"
done
for r in "$W"/glsl/*.raw; do [ -e "$r" ] || continue; n=$(basename "$r" .raw)
    cp "$C/scenes/glsl/$n.json" "$F/seed002/"
    /usr/bin/python3 "$here/raw2exr.py" "$r" "$F/seed002/$n.h100.exr"
done
cp "$W/env.txt" "$F/" 2>/dev/null || true
[ -d "$W/fetches" ] && cp -r "$W/fetches" "$F/"
/usr/bin/python3 "$P/tests/gpu/h100/compare_fixtures.py" "$B/cli/volref" "$F/out" --fixtures "$F" --check --markdown
