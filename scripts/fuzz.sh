#!/usr/bin/env bash
# Runs every libFuzzer target for SECONDS each (default 30) on its seed corpus (docs/robustness.md).
#   scripts/fuzz.sh [SECONDS] [TARGET...]      (targets: fuzz_scene fuzz_nrrd ... ; default: all)
# Needs the sanitize build (cmake --preset sanitize && cmake --build --preset sanitize). New inputs go
# to a scratch corpus, never into tests/fuzz/corpus; a crash is saved under tests/fuzz/regressions/<target>/
# (keep it: ctest in the sanitize build replays every file there) and the script exits 1.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
shift || true
build=build-sanitize
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(fuzz_scene fuzz_nrrd fuzz_nifti fuzz_metaimage fuzz_vtk fuzz_vti fuzz_den fuzz_obj fuzz_ply fuzz_tetrahedra)
fi
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
status=0
for t in "${targets[@]}"; do
  [ -x "$build/tests/fuzz/$t" ] || { echo "fuzz.sh: $build/tests/fuzz/$t is missing (build the sanitize preset)" >&2; exit 2; }
  mkdir -p "$scratch/$t" "tests/fuzz/regressions/$t"
  echo "fuzz.sh: $t for ${seconds} s" >&2
  # -rss_limit_mb: the targets run under a 256 MiB volref memory limit (tests/fuzz/FuzzTarget.h).
  if ! ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp" "$build/tests/fuzz/$t" "$scratch/$t" "tests/fuzz/corpus/$t" \
       -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=20 -print_final_stats=1 \
       -artifact_prefix="tests/fuzz/regressions/$t/" >"$scratch/$t.log" 2>&1; then
    echo "fuzz.sh: $t found a failure (input saved in tests/fuzz/regressions/$t/):" >&2
    grep -E "ERROR|SUMMARY|runtime error|Test unit written" "$scratch/$t.log" | head -20 >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$scratch/$t.log" | tail -1 >&2 || true
  fi
done
exit $status
