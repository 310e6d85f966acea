#!/usr/bin/env bash
# The frame-buffer band as a promise about a slicer volref was not told the arithmetic of (issue 54's
# Done-when): gl_slicer renders SCENE on llvmpipe with its own products and filter; volref renders the same
# scene with neither (blend_products "exact", texture_filter "exact") and with the band
# (profile_options.framebuffer_band), and at least 99.9% of the pixels must lie within the band plus
# 1/255 (`volref compare --tolerance 1/255 --tolerance-from-error`).
# Usage: band_case.sh GL_SLICER VOLREF SCENE.json OUTDIR
set -euo pipefail
slicer=$1 volref=$2 scene=$3 out=$4
name=$(basename "$scene" .json)-band
mkdir -p "$out"
"$slicer" "$scene" "$out/$name-gl.exr" --require-renderer llvmpipe
"$volref" render "$scene" -o "$out/$name-volref.exr" --set render.profile.blend_products=exact \
    --set render.profile.texture_filter=exact --set render.profile_options.framebuffer_band=true
set +e
"$volref" compare "$out/$name-gl.exr" "$out/$name-volref.exr" --tolerance 0.00392156862745098 --tolerance-from-error --json > "$out/$name.json"
rc=$?
set -e
[ $rc -le 1 ] || { echo "band_case.sh: volref compare failed (rc $rc)" >&2; exit 2; }
/usr/bin/python3 - "$out/$name.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
over, pixels = j["overall"]["pixels_over"], j["width"] * j["height"]
print(f"band_case.sh: {over} of {pixels} pixels past the band + 1/255 (max |difference| {j['overall']['max_abs']:.4g})")
sys.exit(0 if over <= 0.001 * pixels else 1)
PY
