#!/usr/bin/env bash
# Proves that a change to the renderer changed no pixel (issue 16): renders every reference scene and
# the benchmark scenes under every projection, order, integrator, profile and path switch (SIMD on/off,
# skipping on/off, the step-doubling estimate) to files of doubles, and compares two such sets bit for bit.
#
#   scripts/image-identity.sh record DIR          render the cases with build/ into DIR (before a change)
#   scripts/image-identity.sh check BEFORE [DIR]  render them again (into DIR, default build/identity-after)
#                                                 and compare with BEFORE; exit 0 iff every image is
#                                                 bitwise identical and every refusal has the same message
#
# Workflow: build the commit before the change, `record /tmp/before`; build the change, `check /tmp/before`.
# The cases are written by this script (DIR/cases.txt); the renders use build/tests/volref_image_dump
# (tests/identity/image_dump.cpp), which calls only load_scene and render_scene. Images are small
# (48 x 48; 16 x 16 for the adaptive integrator) so that the whole set runs in a few minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
DUMP=${VOLREF_IMAGE_DUMP:-build/tests/volref_image_dump}
[[ -x $DUMP ]] || { echo "image-identity: $DUMP is not built (cmake --build build)" >&2; exit 2; }

write_cases() {  # $1: the cases file
    local size="image.width=48 image.height=48" small="image.width=16 image.height=16"
    local scenes=(reference_scenes/*.json bench/vtk/scenes/*.json)
    {
        for s in "${scenes[@]}"; do
            local n extra=""
            n=$(basename "$s" .json)
            [[ $s == bench/* ]] && { n="bench-$n"; extra="volume.source.dims=[64,64,64]"; }
            local base="$size $extra"
            echo "$n|$s|$base|"
            echo "$n.nosimd|$s|$base|nosimd"
            echo "$n.noskip|$s|$base|noskip"
            echo "$n.error|$s|$base|error"
            echo "$n.threads1|$s|$base|threads=1"
            echo "$n.btf|$s|$base render.order=\"back-to-front\"|"
            echo "$n.adaptive|$s|$small $extra render.integrator=\"adaptive\"|"
            for p in mip minip average xray; do
                echo "$n.$p|$s|$base render.projection=\"$p\"|"
                echo "$n.$p.nosimd|$s|$base render.projection=\"$p\"|nosimd"
                echo "$n.$p.adaptive|$s|$small $extra render.projection=\"$p\" render.integrator=\"adaptive\"|"
            done
            echo "$n.firsthit|$s|$base render.projection=\"first-hit\" render.isovalue=0.5|"
            echo "$n.firsthit.adaptive|$s|$small $extra render.projection=\"first-hit\" render.isovalue=0.5 render.integrator=\"adaptive\"|"
            for p in fast vtk-gpu vtk-cpu glsl-basic ospray cuda-curvilinear; do
                echo "$n.$p|$s|$base render.profile=\"$p\"|"
                for q in mip minip average xray; do
                    echo "$n.$p.$q|$s|$base render.profile=\"$p\" render.projection=\"$q\"|"
                done
            done
        done
    } > "$1"
}

render() {  # $1: output folder
    rm -rf "$1"
    mkdir -p "$1"
    write_cases "$1/cases.txt"
    "$DUMP" "$1/cases.txt" "$1"
}

case "${1:-}" in
    record)
        [[ $# -eq 2 ]] || { echo "usage: $0 record DIR" >&2; exit 2; }
        render "$2"
        echo "image-identity: recorded $(ls "$2" | grep -c '\.img$') images and $(ls "$2" | grep -c '\.err$') refusals in $2"
        ;;
    check)
        [[ $# -ge 2 ]] || { echo "usage: $0 check BEFORE [DIR]" >&2; exit 2; }
        before=$2
        after=${3:-build/identity-after}
        render "$after"
        /usr/bin/python3 - "$before" "$after" <<'PY'
import os, struct, sys
before, after = sys.argv[1], sys.argv[2]
def load(path):
    with open(path, "rb") as f:
        data = f.read()
    if path.endswith(".err"):
        return None, data.decode()
    nl = data.index(b"\n")
    n = (len(data) - nl - 1) // 8
    return data[:nl].decode(), struct.unpack(f"={n}d", data[nl + 1:])
names = sorted(n for n in set(os.listdir(before)) | set(os.listdir(after)) if n != "cases.txt")
same = differ = 0
for name in names:
    a, b = os.path.join(before, name), os.path.join(after, name)
    if not os.path.exists(a) or not os.path.exists(b):
        print(f"DIFFERENT {name}: only {'after' if os.path.exists(b) else 'before'}")
        differ += 1
        continue
    if open(a, "rb").read() == open(b, "rb").read():
        same += 1
        continue
    differ += 1
    ha, va = load(a)
    hb, vb = load(b)
    if ha != hb or len(va) != len(vb) or ha is None:
        print(f"DIFFERENT {name}: {va if ha is None else ha} -> {vb if hb is None else hb}")
        continue
    worst = max((abs(x - y) if x == x and y == y else (0.0 if x != x and y != y else float("inf")))
                for x, y in zip(va, vb))
    print(f"DIFFERENT {name}: max |difference| {worst:.3e}")
print(f"image-identity: {same} identical, {differ} different (images and refusals)")
sys.exit(1 if differ else 0)
PY
        ;;
    *)
        echo "usage: $0 record DIR | check BEFORE [DIR]" >&2
        exit 2
        ;;
esac
