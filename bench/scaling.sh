#!/usr/bin/env bash
# bench/scaling.sh: how `volref render` scales with the image size, the volume size and the thread count,
# and its peak memory against the volume size (docs/performance.md, "Scaling and memory").
#
#   bench/scaling.sh                 # about 6 min on 2 idle cores
#   RUNS=1 bench/scaling.sh          # one run per case instead of 3 (a quick look)
#   VOLREF=/path/to/volref MAKE_ML=/path/to/make_ml_volume bench/scaling.sh
#   WAIT_IDLE=0 bench/scaling.sh     # do not wait for an idle machine before each render (default: up to 30 s)
#
# The scene: the Marschner-Lobb volume (fm 6, alpha 0.25) stored as a NRRD file of float32 (4 B per
# voxel, written once per size by bench/make_ml_volume.cpp into a temporary folder; volref keeps the
# voxels in the file's type), the 5-row transfer function of reference_scenes/default.json, trilinear,
# composite front to back, step 0.5 voxel, unshaded, no gradient cache, the default camera (looking
# along -z, the bounding sphere in view); the volume file and the image size are set with --set. Cases:
#   image size   256^2, 512^2, 1024^2, 2048^2 with the 256^3 volume
#   volume size  128^3, 256^3, 384^3, 512^3 at 512^2
#   setup        each volume at 1 x 1 pixel: the fixed part of the render time (reading the file, on
#                one thread; the macrocell grid; Embree scene; camera) and the memory without an image
# Each case runs at 1 and 2 threads, the two interleaved, and the whole list is repeated RUNS times (3),
# so every case sees the machine's load at several moments. "render" is what volref prints on stderr
# ("volref: rendered WxH in S s": render_scene, reading the volume included, file writing excluded);
# "cast" is render minus the median setup time of the same volume and thread count (the ray casting);
# "process" is the wall-clock time of the whole command; peak RSS is /usr/bin/time's %M (the maximum over
# the runs of a case). Medians of RUNS. The raw results are kept in $OUT (default: a temporary file,
# named at the end), with the CPU time of each run and the idle fraction of the machine just before it.
#
# On a shared machine: before each render the script waits (at most WAIT_IDLE seconds, default 30) until
# the CPUs were at least 90% idle over one second (from /proc/stat), so that a render does not start in
# the middle of someone else's build. It cannot stop load that starts during a render: compare the
# runs' spread, and the CPU time with the render time of the 1-thread runs, in the raw results.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
VOLREF=${VOLREF:-$here/build/cli/volref}
MAKE_ML=${MAKE_ML:-$(dirname "$(dirname "$VOLREF")")/bench/make_ml_volume}
RUNS=${RUNS:-3}
WAIT_IDLE=${WAIT_IDLE:-30}
TIME=/usr/bin/time
if [[ ! -x $VOLREF ]]; then
    echo "scaling.sh: $VOLREF not found: build it first (cmake --build build --target volref_cli)" >&2
    exit 1
fi
if [[ ! -x $MAKE_ML ]]; then
    echo "scaling.sh: $MAKE_ML not found: build it first (cmake --build build --target make_ml_volume)" >&2
    exit 1
fi
if [[ ! -x $TIME ]]; then
    echo "scaling.sh: $TIME not found: install it (sudo apt-get install time)" >&2
    exit 1
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/volref-scaling.XXXXXX")
trap 'rm -rf "$work"' EXIT
OUT=${OUT:-$(mktemp "${TMPDIR:-/tmp}/volref-scaling-raw.XXXXXX.tsv")}

cat > "$work/ml.json" <<'EOF'
{
  "volume": {
    "source": "ml256.nrrd",
    "transfer": {
      "color": [[0.0, 0.1, 0.2, 0.6], [0.45, 0.25, 0.5, 0.95], [0.5, 1.0, 0.85, 0.4], [0.55, 1.0, 0.45, 0.15], [1.0, 0.9, 0.1, 0.05]],
      "opacity": [[0.0, 0.0], [0.42, 0.0], [0.5, 0.7], [0.58, 0.0], [1.0, 0.0]],
      "opacity_unit_distance": 1.0
    }
  },
  "image": { "width": 512, "height": 512, "background": [0, 0, 0, 1] },
  "render": { "projection": "composite", "step": 0.5 }
}
EOF

# The fraction of the CPUs' time spent idle over the next second.
idle_fraction() {
    local a b
    a=$(awk '/^cpu /{print $5 + $6, $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9}' /proc/stat)
    sleep 1
    b=$(awk '/^cpu /{print $5 + $6, $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9}' /proc/stat)
    awk -v a="$a" -v b="$b" 'BEGIN { split(a, x, " "); split(b, y, " "); d = y[2] - x[2]; f = 1; if (d > 0) f = (y[1] - x[1]) / d; printf "%.2f", f }'
}

# Waits until the machine is idle (>= 90% over a second), at most WAIT_IDLE seconds; prints the last
# idle fraction.
wait_idle() {
    local deadline=$((SECONDS + WAIT_IDLE)) f=1
    while ((WAIT_IDLE > 0)); do
        f=$(idle_fraction)
        if awk -v f="$f" 'BEGIN { exit !(f >= 0.9) }' || ((SECONDS >= deadline)); then break; fi
    done
    echo "$f"
}

# One render: appends "dims size threads run render_s process_s rss_kib cpu_s idle_before" to $OUT.
run() {
    local dims=$1 size=$2 threads=$3 rep=$4 seconds wall rss cpu idle volume_args
    volume_args=(--set "volume.source=$work/ml$dims.nrrd")
    idle=$(wait_idle)
    "$TIME" -f '%e %M %U %S' -o "$work/time.txt" "$VOLREF" render "$work/ml.json" -o "$work/out.exr" --threads "$threads" \
        "${volume_args[@]}" --set "image.width=$size" --set "image.height=$size" \
        > /dev/null 2> "$work/err.txt" || { cat "$work/err.txt" "$work/time.txt" >&2; exit 1; }
    seconds=$(sed -n 's/^volref: rendered [0-9]*x[0-9]* in \([0-9.]*\) s$/\1/p' "$work/err.txt")
    if [[ -z $seconds ]]; then cat "$work/err.txt" >&2; exit 1; fi
    read -r wall rss user sys < "$work/time.txt"
    cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$dims" "$size" "$threads" "$rep" "$seconds" "$wall" "$rss" "$cpu" "$idle" >> "$OUT"
    printf '  %8s^3 %4s^2 %s thread(s): %7.3f s render, %7.2f s process, %6.2f s CPU, %6d MiB peak RSS (idle before: %s)\n' \
        "$dims" "$size" "$threads" "$seconds" "$wall" "$cpu" "$((rss / 1024))" "$idle" >&2
}

# The resident memory of the program and its libraries alone (no scene).
"$TIME" -f '%M' -o "$work/time.txt" "$VOLREF" --help > /dev/null 2>&1
base_rss=$(tail -n 1 "$work/time.txt")

cases=("256 256" "256 512" "256 1024" "256 2048" "128 512" "384 512" "512 512" "128 1" "256 1" "384 1" "512 1")
volumes="128 256 384 512"
for d in $volumes; do
    "$MAKE_ML" "$d" "$work/ml$d.nrrd"
    echo "$d $((4 * d * d * d))" >> "$work/bytes.txt"  # the samples' bytes (float32)
done
start=$(date +%s)
echo "volref: $VOLREF" >&2
echo "start: $(date -u '+%Y-%m-%d %H:%M UTC'), load average $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores" >&2
: > "$OUT"
for rep in $(seq 1 "$RUNS"); do
    echo "run $rep of $RUNS" >&2
    for c in "${cases[@]}"; do
        read -r dims size <<< "$c"
        for threads in 1 2; do run "$dims" "$size" "$threads" "$rep"; done
    done
done
echo "end: $(date -u '+%Y-%m-%d %H:%M UTC'), load average $(cut -d' ' -f1-3 /proc/loadavg), $(( $(date +%s) - start )) s" >&2

awk -v base_rss="$base_rss" -v runs="$RUNS" -v bytes_file="$work/bytes.txt" '
function med(list,    n, i, j, v, t) {  # the median of space-separated numbers
    n = split(list, v, " ")
    for (i = 2; i <= n; ++i) { t = v[i] + 0; for (j = i - 1; j >= 1 && v[j] + 0 > t; --j) v[j + 1] = v[j]; v[j + 1] = t }
    return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
}
function median(key) { return med(times[key]) }
function medianp(key) { return med(procs[key]) }
BEGIN { while ((getline line < bytes_file) > 0) { split(line, f, " "); fbytes[f[1]] = f[2] } }
{
    key = $1 " " $2 " " $3
    times[key] = times[key] (key in times ? " " : "") $5
    procs[key] = procs[key] (key in procs ? " " : "") $6
    if ($7 > rss[$1 " " $2]) rss[$1 " " $2] = $7
}
END {
    mib = 1048576
    printf "\nMedians of %d runs; cast = render - setup (the same volume at 1 x 1 pixel, same threads).\n", runs
    printf "\nImage size (256^3 float32 volume):\n\n"
    printf "| image | render, 1 thread | render, 2 threads | 1 -> 2 | cast, 1 thread | cast, 2 threads | 1 -> 2 (cast) | cast per pixel, 1 thread | process, 1 / 2 threads | peak RSS |\n"
    printf "|---|---|---|---|---|---|---|---|---|---|\n"
    split("256 512 1024 2048", sizes, " ")
    s1 = median("256 1 1"); s2 = median("256 1 2")
    for (i = 1; i <= 4; ++i) {
        n = sizes[i]; r1 = median("256 " n " 1"); r2 = median("256 " n " 2")
        printf "| %d^2 | %.3f s | %.3f s | %.2fx | %.3f s | %.3f s | %.2fx | %.2f us | %.2f / %.2f s | %.0f MiB |\n", n, r1, r2, r1 / r2,
            r1 - s1, r2 - s2, (r1 - s1) / (r2 - s2), 1e6 * (r1 - s1) / (n * n), medianp("256 " n " 1"), medianp("256 " n " 2"),
            rss["256 " n] / 1024
    }
    printf "\nVolume size (512^2 image):\n\n"
    printf "| volume | setup, 1 / 2 threads | render, 1 thread | render, 2 threads | 1 -> 2 | cast, 1 thread | cast, 2 threads | 1 -> 2 (cast) |\n"
    printf "|---|---|---|---|---|---|---|---|\n"
    split("128 256 384 512", dims, " ")
    for (i = 1; i <= 4; ++i) {
        d = dims[i]; r1 = median(d " 512 1"); r2 = median(d " 512 2"); s1 = median(d " 1 1"); s2 = median(d " 1 2")
        printf "| %d^3 | %.3f / %.3f s | %.3f s | %.3f s | %.2fx | %.3f s | %.3f s | %.2fx |\n", d, s1, s2, r1, r2, r1 / r2,
            r1 - s1, r2 - s2, (r1 - s1) / (r2 - s2)
    }
    printf "\nPeak RSS against volume size (maximum over the runs and thread counts). program: `volref --help` alone,\n"
    printf "%.0f MiB (the executable and its libraries). volume: the samples'"'"' bytes in the file (float32, 4 B per\n", base_rss / 1024
    printf "voxel). image: volref'"'"'s Image in memory, R G B A doubles (32 B per pixel).\n\n"
    printf "| volume | image | peak RSS | volume + image | RSS / (volume + image) | RSS - program | (RSS - program) / (volume + image) |\n"
    printf "|---|---|---|---|---|---|---|\n"
    for (i = 1; i <= 4; ++i) {
        d = dims[i]
        for (k = 0; k < 2; ++k) {
            n = k ? 512 : 1; r = rss[d " " n] * 1024; img = 32 * n * n; vb = fbytes[d]
            printf "| %d^3 | %d^2 | %.0f MiB | %.1f MiB | %.2f | %.0f MiB | %.3f |\n", d, n, r / mib, (vb + img) / mib,
                r / (vb + img), (r - base_rss * 1024) / mib, (r - base_rss * 1024) / (vb + img)
        }
    }
}' "$OUT"
echo
echo "raw results (dims size threads run render_s process_s rss_kib cpu_s idle_before): $OUT"
