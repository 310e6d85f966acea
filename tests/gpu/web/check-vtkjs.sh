#!/usr/bin/env bash
# The ctest test `vtkjs_parity` (issue 22; docs/gpu-checking.md): renders every scene in scenes/ with
# vtk.js 37.4.3 in headless Chromium (render-vtkjs.mjs) and with volref's vtk-js profile, and compares
# each pair with `volref compare --tolerance TOL` (TOL below, derived in docs/gpu-checking.md).
#   check-vtkjs.sh VOLREF OUTDIR [--set PATH=VALUE --expect-fail SCENE]
# With --expect-fail, only SCENE (a name in scenes/) is rendered, volref with the override, and the script
# succeeds only when `volref compare` then reports a difference (exit 1): the check sees that convention.
# Needs /usr/bin/chromium, node and tests/gpu/web/node_modules (scripts/install-deps.sh); without them it
# FAILS (exit 1): it never skips.
set -euo pipefail
volref=${1:?usage: check-vtkjs.sh VOLREF OUTDIR}
out=${2:?usage: check-vtkjs.sh VOLREF OUTDIR}
here="$(cd "$(dirname "$0")" && pwd)"
shift 2
set_args=()
expect_fail=""
while [ $# -gt 0 ]; do
  case "$1" in
    --set) set_args+=(--set "$2"); shift 2 ;;
    --expect-fail) expect_fail="$2"; shift 2 ;;
    *) echo "check-vtkjs.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
# The tolerance per channel (docs/gpu-checking.md, "vtk.js in headless Chromium"): the half-float
# read-back, 2^-11 on values <= 1, plus the volume texture's filtering at 8-bit sub-texel precision,
# sum over a ray's samples of |d alpha / d v| 2^-9 |f(i+1) - f(i)|, at most 5.5e-3 for these scenes.
tol=${VTKJS_TOLERANCE:-0.006}
command -v node >/dev/null || { echo "vtkjs_parity: node is not installed (scripts/install-deps.sh)" >&2; exit 1; }
rm -rf "$out"
mkdir -p "$out"
scenes=("$here"/scenes/*.json)
[ -n "$expect_fail" ] && scenes=("$here/scenes/$expect_fail.json")
node "$here/render-vtkjs.mjs" --out "$out" "${scenes[@]}"
failed=0
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .json)
  "$volref" render "$scene" -o "$out/$name-volref.exr" --threads 2 "${set_args[@]}" >/dev/null
  set +e
  "$volref" compare "$out/$name-vtkjs.tif" "$out/$name-volref.exr" --tolerance "$tol" --json >"$out/$name-compare.json"
  rc=$?
  set -e
  summary=$(/usr/bin/env node -e '
    const j = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
    const c = j.channels;
    console.log(`max abs R ${c.R.max_abs.toExponential(2)} G ${c.G.max_abs.toExponential(2)} B ${c.B.max_abs.toExponential(2)} A ${c.A.max_abs.toExponential(2)}, RMSE ${j.overall.rmse.toExponential(2)}, over ${j.pixels_over}/${j.pixels}, non-finite ${j.non_finite.a}/${j.non_finite.b} (disagree ${j.non_finite.disagree})`);
  ' "$out/$name-compare.json")
  if [ -n "$expect_fail" ]; then
    if [ "$rc" -eq 1 ]; then echo "ok   $name differs with ${set_args[*]}: $summary"; else echo "FAIL $name with ${set_args[*]}: compare exit $rc, expected 1: $summary"; failed=1; fi
  elif [ "$rc" -eq 0 ]; then
    echo "ok   $name: $summary"
  else
    echo "FAIL $name: $summary (volref compare exit $rc)"
    failed=1
  fi
done
exit "$failed"
