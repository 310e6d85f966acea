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
# A case that takes longer than VOLREF_IMAGE_DUMP_TIMEOUT seconds (default 20) is recorded as too slow and
# not compared (the adaptive integrator can run away on some scenes, issue 18); the report counts them.
# Workflow: build the commit before the change, `record /tmp/before`; build the change, `check /tmp/before`.
# The cases are written by this script (DIR/cases.txt); the renders use build/tests/volref_image_dump
# (tests/identity/image_dump.cpp), which calls only load_scene and render_scene. Images are small
# (48 x 48; 8 x 8 for the adaptive integrator) so that the whole set runs in a few minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
DUMP=${VOLREF_IMAGE_DUMP:-build/tests/volref_image_dump}
[[ -x $DUMP ]] || { echo "image-identity: $DUMP is not built (cmake --build build)" >&2; exit 2; }

write_cases() {  # $1: the cases file
    local size="image.width=48 image.height=48" small="image.width=8 image.height=8"
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
            for p in fast vtk-gpu vtk-cpu glsl-basic ospray cuda-curvilinear volumizer; do
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
        echo "image-identity: recorded $(ls "$2" | grep -c '\.img$') images, $(ls "$2" | grep -c '\.err$') refusals and $(ls "$2" | grep -c '\.slow$' || true) cases over the time limit in $2"
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
def case_files(folder):
    out = {}
    for n in os.listdir(folder):
        if n != "cases.txt":
            out[n.rsplit(".", 1)[0]] = os.path.join(folder, n)
    return out
fb, fa = case_files(before), case_files(after)
same = differ = slow = 0
for case in sorted(set(fb) | set(fa)):
    a, b = fb.get(case), fa.get(case)
    if a is None or b is None:
        print(f"DIFFERENT {case}: only {'after' if a is None else 'before'}")
        differ += 1
        continue
    if a.endswith(".slow") or b.endswith(".slow"):
        if a.endswith(".slow") and b.endswith(".slow"):
            slow += 1
        else:
            print(f"DIFFERENT {case}: {os.path.basename(a)} -> {os.path.basename(b)}")
            differ += 1
        continue
    if os.path.basename(a) == os.path.basename(b) and open(a, "rb").read() == open(b, "rb").read():
        same += 1
        continue
    differ += 1
    ha, va = load(a)
    hb, vb = load(b)
    if ha != hb or ha is None or len(va) != len(vb):
        print(f"DIFFERENT {case}: {va if ha is None else ha} -> {vb if hb is None else hb}")
        continue
    worst = max((abs(x - y) if x == x and y == y else (0.0 if x != x and y != y else float("inf")))
                for x, y in zip(va, vb))
    signs = sum(1 for x, y in zip(va, vb) if x == 0 and y == 0 and str(x) != str(y))
    print(f"DIFFERENT {case}: max |difference| {worst:.3e}" + (f" ({signs} zeros changed sign)" if signs else ""))
print(f"image-identity: {same} identical, {differ} different, {slow} too slow in both (not compared)")
sys.exit(1 if differ else 0)
PY
        ;;
    *)
        echo "usage: $0 record DIR | check BEFORE [DIR]" >&2
        exit 2
        ;;
esac
