#!/usr/bin/env bash
# `volref compare --fit --scene` names a real slicer's conventions (issue 54, item 7): gl_slicer renders
# SCENE on llvmpipe; the scene is then given three wrong rules (another orientation, frame buffer and
# correction), and the convention search over that wrong scene must explain gl_slicer's image with the
# scene's own orientation, frame buffer and correction (rgba32f and double count as one: float32 rounding
# is below the search's tolerance).
# Usage: fit_case.sh GL_SLICER VOLREF SCENE.json OUTDIR
# Exit 0 = the search named all three; anything else fails (no GL context is a failure, never a skip).
set -euo pipefail
slicer=$1 volref=$2 scene=$3 out=$4
name=$(basename "$scene" .json)-fit
mkdir -p "$out"
"$slicer" "$scene" "$out/$name-gl.exr" --require-renderer llvmpipe
/usr/bin/python3 - "$scene" "$out/$name-wrong.json" "$out/$name-expected.json" <<'PY'
import json, os, sys
scene, wrong_path, expected_path = sys.argv[1:4]
s = json.load(open(scene))
p = s["render"]["profile"]
base = p.get("base", "reference")
orientation = p.get("slices", {}).get("orientation", "viewport")
framebuffer = p.get("framebuffer", "rgba8" if base == "volumizer" else "double")
correction = p.get("correction", "none" if base == "volumizer" else "pow")
wrong = dict(p)
wrong["slices"] = dict(p.get("slices", {}))
wrong["slices"]["orientation"] = "viewport" if orientation == "axis" else "axis"
wrong["framebuffer"] = "rgba32f" if framebuffer == "rgba8" else "rgba8"
wrong["correction"] = "exact" if correction == "none" else "none"
s["render"]["profile"] = wrong
# the scene's files relative to its folder
src = s["volume"].get("source")
if isinstance(src, str): s["volume"]["source"] = os.path.join(os.path.dirname(os.path.abspath(scene)), src)
json.dump(s, open(wrong_path, "w"))
json.dump({"slices.orientation": orientation, "framebuffer": framebuffer, "correction": correction}, open(expected_path, "w"))
PY
set +e
"$volref" compare "$out/$name-gl.exr" --fit --scene "$out/$name-wrong.json" --json > "$out/$name.json"
rc=$?
set -e
[ $rc -le 1 ] || { echo "fit_case.sh: volref compare failed (rc $rc)" >&2; exit 2; }
/usr/bin/python3 - "$out/$name.json" "$out/$name-expected.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); expected = json.load(open(sys.argv[2]))
rules = r.get("rules", {})
print("fit_case.sh: explained", r.get("explained"), "by", rules, "; expected", expected)
# rgba32f and double differ by float32 rounding, far below the search's tolerance: either names a float buffer.
same = lambda k, v: rules.get(k) == v or (k == "framebuffer" and {rules.get(k), v} <= {"rgba32f", "double"})
ok = r.get("explained") and all(same(k, v) for k, v in expected.items())
sys.exit(0 if ok else 1)
PY
