#!/bin/sh
# Runs the volref-vs-VTK comparison and writes the results to OUT_DIR; bench/run_vtk_comparison.sh
# calls it under xvfb-run (VTK's render windows need an X server) after installing what is missing
# and building volref, then bench/vtk/report.py turns OUT_DIR into docs/performance.md's section.
#
#   xvfb-run -a -s "-screen 0 1024x768x24" bench/vtk/driver.sh OUT_DIR
#
# Settings (environment): VTK_CMP_REPS (5) runs of each renderer per case and thread count,
# VTK_CMP_FRAMES (3) timed frames per VTK run (after 1 warm-up frame), VTK_CMP_THREADS ("1 2"),
# VTK_CMP_CASES ("composite shaded mip dense"), VTK_CMP_REF_STEP (0.0625) the reference's step in
# voxels, VTK_CMP_IDLE (0.9) and VTK_CMP_WAIT_BUDGET (240): before each timed run, wait until the
# CPUs were at least this idle over half a second, spending at most this many seconds waiting in the
# whole run (the machine is shared; the idle fraction of every run goes to OUT_DIR/runs/idle.tsv),
# VTK_CMP_FAST (1) whether to time volref's fast profile too (`--set render.profile=fast`: float SIMD
# lanes and early ray termination at transmittance 2^-10, docs/conventions.md section 9b; 0 skips
# those runs), VOLREF_BUILD (build) the build folder holding cli/volref.
#
# Steps:
#  1. freeze the volref binary: cli/volref, libvolref_core.so.0, libvolref_tools.so.0 and the plugin
#     libvolref_image_files.so (which libvolref_tools loads from its own folder) are copied to
#     OUT_DIR/bin and run from there (LD_LIBRARY_PATH beats the RUNPATH), so a rebuild during the run
#     changes nothing;
#  2. count each scene's samples from the geometry (count_samples.py);
#  3. render each case's reference with volref at step VTK_CMP_REF_STEP voxel (EXR);
#  4. the timing loop, interleaved: for each rep, for each thread count, for each case:
#     volref (one render), volref's set-up (the same scene at 1 x 1 pixel: volume generation and the
#     rest of the fixed cost), volref's fast profile and its own set-up (the same two runs with
#     `--set render.profile=fast`; files *-fast-* and *-fastsetup-*, unless VTK_CMP_FAST=0), VTK
#     fixed-point, VTK GPU. Each run's numbers go to OUT_DIR/runs/ as one JSON file; the last image of
#     each renderer and thread count to OUT_DIR/images/.
# A VTK run that fails leaves its stderr in OUT_DIR/runs/*.err and the loop goes on.
set -eu

if [ $# -ne 1 ]; then echo "usage: $0 OUT_DIR" >&2; exit 2; fi
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=$1
mkdir -p "$out"
out=$(cd "$out" && pwd)
reps=${VTK_CMP_REPS:-5}
frames=${VTK_CMP_FRAMES:-3}
threads_list=${VTK_CMP_THREADS:-"1 2"}
cases=${VTK_CMP_CASES:-"composite shaded mip dense"}
ref_step=${VTK_CMP_REF_STEP:-0.0625}
idle_min=${VTK_CMP_IDLE:-0.9}
wait_left=$(( ${VTK_CMP_WAIT_BUDGET:-240} * 2 ))   # in half seconds
fast=${VTK_CMP_FAST:-1}
build=${VOLREF_BUILD:-$root/build}
py=/usr/bin/python3          # Debian's Python: python3-vtk9 and python3-numpy live there
ref_threads=$(nproc)
case "$fast" in 0 | 1) ;; *) echo "$0: VTK_CMP_FAST must be 0 or 1, not '$fast'" >&2; exit 2 ;; esac

rm -rf "${out:?}/bin" "${out:?}/runs" "${out:?}/images" "${out:?}/ref" "${out:?}/samples"
mkdir -p "$out/bin" "$out/runs" "$out/images" "$out/ref" "$out/samples"

log() { printf '%s [%s] %s\n' "$(date +%H:%M:%S)" "vtk-comparison" "$*" >&2; }
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.4f", b - a }'; }

# The fraction of CPU time spent idle (idle + iowait, all CPUs) over the next half second.
idle_fraction() {
    a=$(head -n 1 /proc/stat); sleep 0.5; b=$(head -n 1 /proc/stat)
    printf '%s\n%s\n' "$a" "$b" | awk '{ t = 0; for (i = 2; i <= NF; i++) t += $i; idle = $5 + $6 }
        NR == 1 { t0 = t; i0 = idle } NR == 2 { printf "%.3f", (t > t0) ? (idle - i0) / (t - t0) : 1 }'
}

# Waits (within the budget) until the CPUs are idle; records the run's name, the idle fraction just
# before it and the half seconds waited in runs/idle.tsv.
wait_idle() {
    waited=0
    frac=$(idle_fraction)
    while [ "$wait_left" -gt 0 ] && awk -v f="$frac" -v m="$idle_min" 'BEGIN { exit !(f < m) }'; do
        frac=$(idle_fraction)
        wait_left=$((wait_left - 1))
        waited=$((waited + 1))
    done
    printf '%s\t%s\t%s\n' "$1" "$frac" "$waited" >>"$out/runs/idle.tsv"
}

# 1. Freeze the binary.
cp "$build/cli/volref" "$out/bin/volref"
for lib in libvolref_core.so.0 libvolref_tools.so.0 libvolref_image_files.so; do cp -L "$build/$lib" "$out/bin/$lib"; done
volref() { LD_LIBRARY_PATH="$out/bin${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$out/bin/volref" "$@"; }

# Runs volref once: $1 = JSON file to write, the rest = volref's arguments. Records the render
# time volref prints ("volref: rendered WxH in S s") and the whole process's wall-clock time.
timed_volref() {
    json=$1; shift
    t0=$(now)
    if ! volref "$@" 2>"$json.err" >/dev/null; then
        echo "volref failed: volref $*" >&2; cat "$json.err" >&2; exit 1
    fi
    t1=$(now)
    render=$(sed -n 's/^volref: rendered [0-9]*x[0-9]* in \([0-9.]*\) s$/\1/p' "$json.err" | tail -n 1)
    if [ -z "$render" ]; then echo "volref printed no render time:" >&2; cat "$json.err" >&2; exit 1; fi
    printf '{"render_s": %s, "process_s": %s}\n' "$render" "$(elapsed "$t0" "$t1")" >"$json"
    rm -f "$json.err"
}

# Runs VTK once: $1 = JSON file, $2 = mapper, $3 = threads, $4 = scene, $5 = PNG.
timed_vtk() {
    if LP_NUM_THREADS=$3 "$py" "$here/vtk_render.py" "$4" --mapper "$2" --threads "$3" \
        --frames "$frames" --warmup 1 -o "$5" >"$1.out" 2>"$1.err"; then
        tail -n 1 "$1.out" >"$1"
        rm -f "$1.out"
        [ -s "$1.err" ] || rm -f "$1.err"
    else
        log "VTK $2 failed (exit $?), see $1.err"
        rm -f "$1.out"
    fi
}

load_start=$(cut -d' ' -f1-3 /proc/loadavg)

# 2. Samples per scene.
for c in $cases; do
    "$py" "$here/count_samples.py" "$here/scenes/$c.json" >"$out/samples/$c.json"
done
log "sample counts in $out/samples"

# 3. References.
for c in $cases; do
    log "reference $c (step $ref_step voxel, $ref_threads threads)"
    timed_volref "$out/ref/$c.json" render "$here/scenes/$c.json" -o "$out/ref/$c.exr" \
        --threads "$ref_threads" --set "render.step=$ref_step"
done

# 4. The interleaved timing loop.
rep=1
while [ "$rep" -le "$reps" ]; do
    for t in $threads_list; do
        for c in $cases; do
            scene="$here/scenes/$c.json"
            if [ "$fast" = 1 ]; then
                log "rep $rep/$reps, $t thread(s), $c: volref, set-up, volref fast, fast set-up, VTK fixed-point, VTK GPU"
            else
                log "rep $rep/$reps, $t thread(s), $c: volref, set-up, VTK fixed-point, VTK GPU"
            fi
            wait_idle "$c-t$t-volref-$rep"
            timed_volref "$out/runs/$c-t$t-volref-$rep.json" render "$scene" \
                -o "$out/images/$c-volref-t$t.png" --threads "$t"
            wait_idle "$c-t$t-setup-$rep"
            timed_volref "$out/runs/$c-t$t-setup-$rep.json" render "$scene" \
                -o "$out/runs/setup.png" --threads "$t" --set image.width=1 --set image.height=1
            if [ "$fast" = 1 ]; then
                wait_idle "$c-t$t-fast-$rep"
                timed_volref "$out/runs/$c-t$t-fast-$rep.json" render "$scene" \
                    -o "$out/images/$c-fast-t$t.png" --threads "$t" --set render.profile=fast
                wait_idle "$c-t$t-fastsetup-$rep"
                timed_volref "$out/runs/$c-t$t-fastsetup-$rep.json" render "$scene" \
                    -o "$out/runs/setup.png" --threads "$t" --set image.width=1 --set image.height=1 \
                    --set render.profile=fast
            fi
            wait_idle "$c-t$t-fixed-$rep"
            timed_vtk "$out/runs/$c-t$t-fixed-$rep.json" fixed "$t" "$scene" "$out/images/$c-fixed-t$t.png"
            wait_idle "$c-t$t-gpu-$rep"
            timed_vtk "$out/runs/$c-t$t-gpu-$rep.json" gpu "$t" "$scene" "$out/images/$c-gpu-t$t.png"
        done
    done
    rep=$((rep + 1))
done
rm -f "$out/runs/setup.png"

# 5. The shaded case once more with the light VTK creates by itself (ambient colour (0, 0, 0)), to
#    show what the explicit white headlight changes (image only, not timed).
case " $cases " in *" shaded "*)
    t=$(echo "$threads_list" | tr ' ' '\n' | sort -n | tail -n 1)
    for m in fixed gpu; do
        log "shaded, VTK $m with VTK's default light"
        LP_NUM_THREADS=$t "$py" "$here/vtk_render.py" "$here/scenes/shaded.json" --mapper "$m" --threads "$t" \
            --frames 0 --warmup 1 --light default -o "$out/images/shaded-$m-defaultlight.png" >/dev/null \
            2>"$out/runs/shaded-$m-defaultlight.err" || log "VTK $m with the default light failed"
        [ -s "$out/runs/shaded-$m-defaultlight.err" ] || rm -f "$out/runs/shaded-$m-defaultlight.err"
    done ;;
esac
printf '{"reps": %s, "frames": %s, "threads": "%s", "cases": "%s", "ref_step": %s, "ref_threads": %s, "idle_min": %s, "wait_budget_s": %s, "fast": %s, "loadavg_start": "%s", "loadavg_end": "%s"}\n' \
    "$reps" "$frames" "$threads_list" "$cases" "$ref_step" "$ref_threads" "$idle_min" "${VTK_CMP_WAIT_BUDGET:-240}" "$fast" \
    "$load_start" "$(cut -d' ' -f1-3 /proc/loadavg)" >"$out/settings.json"
log "done: results in $out"
