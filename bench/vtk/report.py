#!/usr/bin/python3
"""Turns the results of bench/vtk/driver.sh into the "## volref beside VTK" section of
docs/performance.md (replacing that section if it exists, appending it otherwise).

    /usr/bin/python3 bench/vtk/report.py OUT_DIR --doc docs/performance.md \
        --command "bench/run_vtk_comparison.sh" [--start EPOCH_SECONDS]

Medians: volref's over the runs (one render per run), VTK's over all timed frames of all runs.
volref's "frame" is its render time minus its set-up time (the same scene rendered at 1 x 1 pixel:
generating the 256^3 volume and building the pipeline), since VTK's per-volume work happens in its
untimed warm-up frame. FPS = 1 / median frame time. Samples per second use the sample count of
count_samples.py (volref's exact count at step 1 voxel) for every renderer. Errors: compare.py,
against volref's reference render (step OUT_DIR/settings.json ref_step), images of the largest
thread count. volref's fast profile (`--set render.profile=fast`: runs/*-fast-*.json with their own
set-up runs/*-fastsetup-*.json, images/*-fast-t*.png; VTK_CMP_FAST=1 in driver.sh) is reported like
volref's default when its runs are there; without them the section is the same as before.
"""
import argparse
import datetime
import glob
import json
import os
import platform
import statistics
import subprocess
import sys
import textwrap
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402

HEADING = "## volref beside VTK"
CASE_TITLES = {
    "composite": "composite, unshaded",
    "shaded": "composite, shaded",
    "mip": "MIP",
    "dense": "composite, dense TF",
}
RENDERERS = [("volref", "volref, step 1"), ("fast", "volref fast, step 1"), ("fixed", "VTK fixed-point"),
             ("gpu", "VTK GPU (llvmpipe)")]


def load(path):
    with open(path) as f:
        return json.load(f)


def median(values):
    return statistics.median(values) if values else None


def fmt(x, digits=3):
    return "—" if x is None else f"{x:.{digits}g}" if abs(x) < 1000 else f"{x:.0f}"


def fps(frame):
    """Frames per second of a frame time in seconds (None when there is none)."""
    return 1.0 / frame if frame and frame > 0 else None


def fixed(x, decimals):
    return "—" if x is None else f"{x:.{decimals}f}"


def collect(out, settings):
    cases = settings["cases"].split()
    threads = [int(t) for t in settings["threads"].split()]
    res = {}
    for c in cases:
        for t in threads:
            r = {"failures": []}
            for kind in ("volref", "setup", "fast", "fastsetup"):
                runs = [load(p) for p in sorted(glob.glob(f"{out}/runs/{c}-t{t}-{kind}-*.json"))]
                r[kind + "_render"] = median([x["render_s"] for x in runs])
                r[kind + "_process"] = median([x["process_s"] for x in runs])
                r[kind + "_n"] = len(runs)
            r["volref_frame"] = (r["volref_render"] - r["setup_render"]
                                 if r["volref_render"] is not None and r["setup_render"] is not None else None)
            r["fast_frame"] = (r["fast_render"] - r["fastsetup_render"]
                               if r["fast_render"] is not None and r["fastsetup_render"] is not None else None)
            for m in ("fixed", "gpu"):
                runs = [load(p) for p in sorted(glob.glob(f"{out}/runs/{c}-t{t}-{m}-*.json"))]
                frames = [f for x in runs for f in x["frames_s"]]
                r[m + "_frame"] = median(frames)
                r[m + "_warmup"] = median([w for x in runs for w in x["warmup_s"]])
                r[m + "_n"] = len(frames)
                r[m + "_info"] = runs[0] if runs else None
                for e in sorted(glob.glob(f"{out}/runs/{c}-t{t}-{m}-*.json.err")):
                    if not os.path.exists(e[:-4]):
                        with open(e) as f:
                            lines = [ln.strip() for ln in f if ln.strip()]
                        r["failures"].append((m, os.path.basename(e), lines[-3:] if lines else ["(no output)"]))
            res[(c, t)] = r
    return cases, threads, res


def image_errors(out, cases, threads):
    errs, same = {}, {}
    tmax = max(threads)
    for c in cases:
        ref_path = f"{out}/ref/{c}.exr"
        if not os.path.exists(ref_path):
            continue
        ref = compare.read_image(ref_path)
        rgb = ref[..., :3]
        errs[(c, "floor")] = compare.errors(rgb, compare.quantised(rgb))
        errs[(c, "ref_alpha")] = int(np.count_nonzero(ref[..., 3] > 0))
        for m, _ in RENDERERS:
            p = f"{out}/images/{c}-{m}-t{tmax}.png"
            if not os.path.exists(p):
                continue
            img = compare.read_rgb(p)
            errs[(c, m)] = compare.errors(rgb, img)
            light = f"{out}/images/{c}-{m}-defaultlight.png"
            if os.path.exists(light):
                errs[(c, m + "_defaultlight")] = compare.errors(rgb, compare.read_rgb(light))
            for t in threads:
                q = f"{out}/images/{c}-{m}-t{t}.png"
                if t != tmax and os.path.exists(q):
                    d = float(np.max(np.abs(compare.read_rgb(q) - img)))
                    same[(c, m, t)] = d
    return errs, same


def machine(out, res):
    cpu = ""
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")), "")
    except OSError:
        pass
    try:
        with open("/etc/debian_version") as f:
            debian = f.read().strip()
    except OSError:
        debian = "?"
    info = next((r[m + "_info"] for r in res.values() for m in ("gpu", "fixed") if r[m + "_info"]), None) or {}
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    try:
        commit = subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "?"
    return {"cpu": cpu, "cores": os.cpu_count(), "debian": debian, "kernel": platform.release(),
            "vtk": info.get("vtk_version", "?"), "gl_renderer": info.get("gl_renderer", "?"),
            "gl_version": info.get("gl_version", "?"), "commit": commit}


def default_light_note(errs):
    f, fd = errs.get(("shaded", "fixed")), errs.get(("shaded", "fixed_defaultlight"))
    g, gd = errs.get(("shaded", "gpu")), errs.get(("shaded", "gpu_defaultlight"))
    if not (f and fd):
        return ""
    text = (f" With VTK's own light (`vtk_render.py --light default`, rendered once by this run) the shaded "
            f"fixed-point image's RMSE is {fd['rmse']:.4f} instead of {f['rmse']:.4f}")
    if g and gd:
        text += (f" (GPU: {gd['rmse']:.4f} either way)" if abs(gd["rmse"] - g["rmse"]) < 5e-5
                 else f" (GPU: {gd['rmse']:.4f} instead of {g['rmse']:.4f})")
    return text + "."


def closest_note(ratios):
    if not ratios:
        return ""
    by_case = {}
    for r, c, t in ratios:
        by_case.setdefault(c, []).append(r)
    best = max(by_case, key=lambda c: max(by_case[c]))
    worst = min(by_case, key=lambda c: min(by_case[c]))
    return (f" Measured here, volref comes closest to the fixed-point mapper in the {best} case "
            f"({'x, '.join(f'{r:.2f}' for r in by_case[best])}x at {', '.join(str(t) for _, c, t in ratios if c == best)} "
            f"thread(s)) and is furthest behind in the {worst} case "
            f"({'x, '.join(f'{r:.2f}' for r in by_case[worst])}x).")


def short_of(values, target, unit, short_text):
    """How values (one per case and thread count) stand against a target they should reach: short_text
    (formatted with a = target / max, b = target / min) when all are below it."""
    lo, hi = min(values), max(values)
    if hi < target:
        return short_text.format(a=target / hi, b=target / lo)
    if lo >= target:
        return f"at least {target:g}{unit} in all {len(values)} case and thread-count pairs"
    n = sum(1 for v in values if v >= target)
    return f"at least {target:g}{unit} in {n} of {len(values)} case and thread-count pairs"


def idle_note(out, settings):
    path = f"{out}/runs/idle.tsv"
    if not os.path.exists(path):
        return ""
    rows = []
    with open(path) as f:
        for ln in f:
            parts = ln.split("\t")
            if len(parts) == 3:
                rows.append((parts[0], float(parts[1]), int(parts[2])))
    if not rows:
        return ""
    m = settings.get("idle_min", 0.9)
    ok = sum(1 for _, frac, _ in rows if frac >= m)
    waited = sum(w for _, _, w in rows) / 2.0
    text = (f" Before each of the {len(rows)} timed runs the script waited until the CPUs had been at least "
            f"{m * 100:.0f}% idle over half a second (at most {settings.get('wait_budget_s', '?')} s of waiting "
            f"in all): {ok} of {len(rows)} runs started that way, after {waited:.0f} s of waiting in total")
    return text + ("." if ok == len(rows) else "; the others started when the budget was spent.")


def section(out, args):
    settings = load(f"{out}/settings.json")
    cases, threads, res = collect(out, settings)
    samples = {c: load(f"{out}/samples/{c}.json") for c in cases}
    refs = {c: load(f"{out}/ref/{c}.json") for c in cases if os.path.exists(f"{out}/ref/{c}.json")}
    errs, same = image_errors(out, cases, threads)
    has_fast = any(r["fast_n"] for r in res.values())
    mach = machine(out, res)
    reps, frames = settings["reps"], settings["frames"]
    tmax = max(threads)
    date = args.date or datetime.date.today().isoformat()
    L = []
    w = L.append

    w(HEADING)
    w("")
    w("*Written by `bench/run_vtk_comparison.sh` (bench/vtk/report.py); rerunning the command replaces this "
      "section.*")
    w("")
    w("The same scene rendered by volref and by VTK 9.1's two CPU-reachable volume mappers: "
      "`vtkFixedPointVolumeRayCastMapper` (CPU, multithreaded) and `vtkGPUVolumeRayCastMapper`, which on "
      f"this machine runs on **Mesa's llvmpipe**, a software OpenGL rasteriser on the CPU ({mach['gl_renderer']}; "
      "no GPU here), so its numbers say nothing about a real GPU. Scene (bench/vtk/scenes/*.json, written by "
      "bench/vtk/make_scenes.py; the VTK script reads the same JSON files): Marschner-Lobb 256^3 float32 "
      "(fm 6, alpha 0.25; generated by volref as doubles, by VTK as float32) over [-127.5, 127.5]^3, spacing 1, 512 x 512 pixels, "
      "perspective camera 739.5 units from the centre at azimuth -60 and elevation 25 degrees "
      "(eye = 739.5 (cos el sin az, sin el, cos el cos az), up +y), fov 30, one white headlight, trilinear "
      "interpolation, sample distance 1 voxel (VTK: `SetSampleDistance(1)`, `AutoAdjustSampleDistancesOff()`, "
      "`SetInterpolationTypeToLinear()`, fixed-point `ImageSampleDistance` 1, no jittering). Cases: "
      "**composite** (a semi-transparent band around f = 0.5, opacity 0.5 per 4 units), **shaded** (the same "
      "with Blinn-Phong ka 0.2, kd 0.7, ks 0.3, n 10), **mip** (colours over [0.6, 1], opacity ramp 0.5 to 1), "
      "**dense** (opacity 0.002 per unit at f = 0 to 0.02 at f = 1: every sample contributes).")
    w("")
    w("Two choices make the shaded scene the same scene in both programs. (1) `two_sided: true` in volref: "
      "VTK's renderers light both sides by default (`TwoSidedLighting` on), and the GPU mapper's normal is "
      "+grad f (docs/conventions.md section 9), so only two-sided lighting agrees. (2) VTK gets an explicit "
      "headlight with ambient, diffuse and specular colour (1, 1, 1): the light VTK creates by itself has "
      "ambient colour (0, 0, 0), and the fixed-point mapper multiplies ka by it (the GPU mapper ignores the "
      "light's colour for ambient)." + default_light_note(errs))
    w("")

    # Frame rates.
    w(f"**Frame rates** (medians: volref over {reps} runs, VTK over {reps} runs x {frames} timed frames after "
      "one warm-up frame per run; all runs interleaved: volref, volref set-up, "
      + ("volref fast, fast set-up, " if has_fast else "") +
      "fixed-point, GPU, for each case "
      "and thread count in turn, repeated). *render*: the time `volref render` prints, which includes "
      "generating the 256^3 volume; *set-up*: the same command at 1 x 1 pixel (volume generation and pipeline "
      "set-up, one thread); *frame* = render - set-up, the part comparable with VTK's frames (VTK's volume "
      "creation and per-volume work, such as the fixed-point mapper's gradient encoding and min/max blocks and "
      "the GPU mapper's texture upload and shader compilation, fall in its untimed warm-up frame). *process*: "
      "the whole volref command, wall clock.")
    w("")
    w("| case | threads | volref render | set-up | frame | process | volref FPS | fixed-point FPS | GPU (llvmpipe) FPS | volref / fixed-point | volref / GPU |")
    w("|---|---|---|---|---|---|---|---|---|---|---|")
    ratios_fixed, ratios_render = [], []
    for c in cases:
        for t in threads:
            r = res[(c, t)]
            vf = r["volref_frame"]
            v_fps, f_fps, g_fps = fps(vf), fps(r["fixed_frame"]), fps(r["gpu_frame"])
            rf = v_fps / f_fps if v_fps and f_fps else None
            rg = v_fps / g_fps if v_fps and g_fps else None
            if rf:
                ratios_fixed.append((rf, c, t))
                if r["volref_render"]:
                    ratios_render.append((1.0 / r["volref_render"]) / f_fps)
            w(f"| {CASE_TITLES.get(c, c)} | {t} | {fixed(r['volref_render'], 2)} s | {fixed(r['setup_render'], 2)} s | "
              f"{fixed(vf, 2)} s | {fixed(r['volref_process'], 2)} s | {fixed(v_fps, 2)} | "
              f"{fixed(f_fps, 2) if f_fps else 'failed'} | {fixed(g_fps, 2) if g_fps else 'failed'} | "
              f"{fixed(rf, 3)} | {fixed(rg, 2)} |")
    w("")
    if ratios_render:
        w(f"volref FPS = 1 / frame. Counted on volref's whole render time instead (volume generation included), "
          f"volref / fixed-point would be {min(ratios_render):.2f}x to {max(ratios_render):.2f}x.")
        w("")
    fast_ratios_fixed = []
    if has_fast:
        w(f"**volref's fast profile** (`--set render.profile=fast`, the same scenes otherwise), timed like the "
          f"default: medians over {reps} runs, *set-up* its own run at 1 x 1 pixel with the fast profile, "
          "*frame* = render - set-up, FPS = 1 / frame. *fast / default*: its FPS over the default volref FPS "
          "above.")
        w("")
        w("| case | threads | fast render | set-up | frame | process | fast FPS | fast / default | fast / fixed-point | fast / GPU |")
        w("|---|---|---|---|---|---|---|---|---|---|")
        fast_ratios_render = []
        for c in cases:
            for t in threads:
                r = res[(c, t)]
                ff = r["fast_frame"]
                q_fps, v_fps = fps(ff), fps(r["volref_frame"])
                f_fps, g_fps = fps(r["fixed_frame"]), fps(r["gpu_frame"])
                rv = q_fps / v_fps if q_fps and v_fps else None
                rf = q_fps / f_fps if q_fps and f_fps else None
                rg = q_fps / g_fps if q_fps and g_fps else None
                if rf:
                    fast_ratios_fixed.append((rf, c, t))
                    if r["fast_render"]:
                        fast_ratios_render.append((1.0 / r["fast_render"]) / f_fps)
                w(f"| {CASE_TITLES.get(c, c)} | {t} | {fixed(r['fast_render'], 2)} s | "
                  f"{fixed(r['fastsetup_render'], 2)} s | {fixed(ff, 2)} s | {fixed(r['fast_process'], 2)} s | "
                  f"{fixed(q_fps, 2)} | {fixed(rv, 2)} | {fixed(rf, 3)} | {fixed(rg, 2)} |")
        w("")
        if fast_ratios_render:
            w(f"Counted on the fast profile's whole render time instead (volume generation included), fast / "
              f"fixed-point would be {min(fast_ratios_render):.2f}x to {max(fast_ratios_render):.2f}x.")
            w("")

    # Samples per second.
    w("**Samples per second.** Samples per frame = volref's exact count at step 1 voxel "
      "(bench/vtk/count_samples.py: volref's pixel rays rebuilt in numpy, the slab test against the domain, "
      "max(1, ceil(L / h - 1e-9)) samples per ray of chord L; rays hitting x mean chord / step differs from it "
      f"by at most {max(abs(s['samples'] - s['estimate']) / s['samples'] for s in samples.values()) * 100:.2f}%); the same count is used for VTK, which at the same sample distance takes the same number of "
      "samples per ray give or take one, but its fixed-point mapper skips empty 4^3 blocks and stops rays early "
      "(remaining transparency below 255/32767), so for it these are *equivalent* samples per second (the work volref does), not "
      "samples it evaluated; likewise volref's own count includes the segments its empty-space skipping passes "
      "over (as in \"Whole renders\" above)"
      + ("; volref's fast profile is counted the same way, so its count also includes the samples its rays "
         "leave out after early termination" if has_fast else "") +
      ". Per core = / threads (llvmpipe at LP_NUM_THREADS=1 still rasterises on one "
      "worker thread plus the main thread).")
    w("")
    if has_fast:
        w("| case | rays hitting | mean chord | samples per frame | threads | volref M/s (per core) | volref fast M/s (per core) | fixed-point M/s (per core) | GPU M/s (per core) |")
        w("|---|---|---|---|---|---|---|---|---|")
    else:
        w("| case | rays hitting | mean chord | samples per frame | threads | volref M/s (per core) | fixed-point M/s (per core) | GPU M/s (per core) |")
        w("|---|---|---|---|---|---|---|---|")
    per_core, fast_per_core = [], []
    for c in cases:
        s = samples[c]
        for i, t in enumerate(threads):
            r = res[(c, t)]
            cells = []
            for m in ("volref", "fast", "fixed", "gpu") if has_fast else ("volref", "fixed", "gpu"):
                ft = r[m + "_frame"]
                if ft and ft > 0:
                    rate = s["samples"] / ft / 1e6
                    cells.append(f"{rate:.1f} ({rate / t:.1f})")
                    if m == "volref":
                        per_core.append((rate / t, c, t))
                    elif m == "fast":
                        fast_per_core.append((rate / t, c, t))
                else:
                    cells.append("—")
            lead = (f"| {CASE_TITLES.get(c, c)} | {s['hits']} | {s['mean_chord']:.1f} | {s['samples'] / 1e6:.2f} M"
                    if i == 0 else "| | | |")
            w(f"{lead} | {t} | " + " | ".join(cells) + " |")
    w("")
    check = ("Estimate check: hits x mean chord / step = "
             + ", ".join(f"{samples[c]['estimate'] / 1e6:.2f} M ({c})" for c in cases) + ".")
    if "dense" in cases and (("dense", "ref_alpha") in errs):
        check += (f" In the dense case every ray that meets the volume gets alpha > 0: the reference image has "
                  f"{errs[('dense', 'ref_alpha')]} such pixels, count_samples.py counts {samples['dense']['hits']} "
                  "rays hitting.")
    w(check)
    w("")

    # Errors.
    ref_step = settings["ref_step"]
    w(f"**Error against volref's most accurate reference**: volref with `render.step` {ref_step} voxel "
      f"({1 / ref_step:.0f} samples per voxel, EXR, double precision throughout), the same scene otherwise. "
      "Each image (volref at step 1"
      + (" with its default and its fast profile" if has_fast else "") +
      ", VTK's two mappers; the "
      f"{tmax}-thread runs' last images) is compared as RGB in [0, 1] over opaque black: RMSE over all "
      "512 x 512 pixels and 3 channels (background included) / largest absolute difference. All "
      + ("four" if has_fast else "three") + " are "
      "8-bit PNGs (VTK's window is 8 bits per channel), so none can be better than the *8-bit floor*: the "
      "reference itself rounded to 8 bits.")
    w("")
    if has_fast:
        w("| case | reference render | 8-bit floor | volref, step 1 | volref fast, step 1 | VTK fixed-point | VTK GPU (llvmpipe) |")
        w("|---|---|---|---|---|---|---|")
    else:
        w("| case | reference render | 8-bit floor | volref, step 1 | VTK fixed-point | VTK GPU (llvmpipe) |")
        w("|---|---|---|---|---|---|")
    lower, fast_lower = [], []
    for c in cases:
        def cell(key):
            e = errs.get((c, key))
            return "—" if e is None else f"{e['rmse']:.4f} / {e['max']:.3f}"
        rr = refs.get(c)
        w(f"| {CASE_TITLES.get(c, c)} | {fixed(rr['render_s'], 1) if rr else '—'} s | {cell('floor')} | "
          f"{cell('volref')} | " + (f"{cell('fast')} | " if has_fast else "") + f"{cell('fixed')} | {cell('gpu')} |")
        if (c, "volref") in errs and (c, "fixed") in errs:
            lower.append((c, errs[(c, "volref")]["rmse"], errs[(c, "fixed")]["rmse"]))
        if (c, "fast") in errs and (c, "fixed") in errs:
            fast_lower.append((c, errs[(c, "fast")]["rmse"], errs[(c, "fixed")]["rmse"]))
    w("")
    diffs = [f"{m} {c} {t} vs {tmax} threads: {d:.4f}" for (c, m, t), d in sorted(same.items()) if d > 0]
    if same:
        w("Thread count and images: " + ("every renderer's image at " + ", ".join(str(t) for t in threads if t != tmax)
          + f" thread(s) is identical to its {tmax}-thread image." if not diffs else
          "images that differ between thread counts (largest difference): " + "; ".join(diffs) + "."))
        w("")

    failures = [(c, t, f) for (c, t), r in res.items() for f in r["failures"]]
    if failures:
        w("**Failures**: " + "; ".join(f"{m} on {c} at {t} thread(s) ({name}): `{' / '.join(lines)}`"
                                       for c, t, (m, name, lines) in failures) + ".")
        w("")

    # Targets.
    w("**Against the targets** (at least 3x vtkFixedPointVolumeRayCastMapper's FPS with lower error; "
      ">= 500 M trilinear samples/s/core):")
    w("")
    if ratios_fixed:
        lo, hi = min(ratios_fixed), max(ratios_fixed)
        w(f"- FPS: volref reaches {lo[0]:.3f}x ({lo[1]}, {lo[2]} thread(s)) to {hi[0]:.3f}x ({hi[1]}, {hi[2]} "
          f"thread(s)) of the fixed-point mapper's frame rate on frame time alone; reaching 3x needs a "
          f"{3 / hi[0]:.1f}x to {3 / lo[0]:.1f}x speed-up.")
    if fast_ratios_fixed:
        lo, hi = min(fast_ratios_fixed), max(fast_ratios_fixed)
        w(f"- FPS, fast profile: it reaches {lo[0]:.3f}x ({lo[1]}, {lo[2]} thread(s)) to {hi[0]:.3f}x ({hi[1]}, {hi[2]} "
          "thread(s)) of the fixed-point mapper's frame rate on frame time alone; "
          + short_of([x[0] for x in fast_ratios_fixed], 3, "x", "reaching 3x needs a {a:.1f}x to {b:.1f}x speed-up")
          + ".")
    if per_core:
        lo, hi = min(per_core), max(per_core)
        w(f"- Throughput: {lo[0]:.1f} ({lo[1]}, {lo[2]} thread(s)) to {hi[0]:.1f} ({hi[1]}, {hi[2]} thread(s)) "
          f"M samples/s/core, {500 / hi[0]:.1f}x to {500 / lo[0]:.1f}x short of 500 M/s/core.")
    if fast_per_core:
        lo, hi = min(fast_per_core), max(fast_per_core)
        w(f"- Throughput, fast profile: {lo[0]:.1f} ({lo[1]}, {lo[2]} thread(s)) to {hi[0]:.1f} ({hi[1]}, "
          f"{hi[2]} thread(s)) M samples/s/core, "
          + short_of([x[0] for x in fast_per_core], 500, " M/s/core", "{a:.1f}x to {b:.1f}x short of 500 M/s/core")
          + ".")
    if lower:
        better = [c for c, v, f in lower if v < f]
        w(f"- Error: volref's step-1 image has a lower RMSE than the fixed-point mapper's in {len(better)} of "
          f"{len(lower)} cases" + (f" ({', '.join(better)})" if better else "") +
          "; " + ", ".join(f"{c} {v:.4f} vs {f:.4f}" for c, v, f in lower) + ".")
    if fast_lower:
        better = [c for c, v, f in fast_lower if v < f]
        w(f"- Error, fast profile: its step-1 image has a lower RMSE than the fixed-point mapper's in "
          f"{len(better)} of {len(fast_lower)} cases" + (f" ({', '.join(better)})" if better else "") +
          "; " + ", ".join(f"{c} {v:.4f} vs {f:.4f}" for c, v, f in fast_lower) + ".")
    w("")
    w((WHY.replace(WHY_FAST_AFTER, WHY_FAST_AFTER + WHY_FAST) if has_fast else WHY) + closest_note(ratios_fixed))
    w("")

    # Command and machine.
    total = f"{(time.time() - args.start) / 60:.1f} min" if args.start else None
    w(f"Command ({date}; volref commit {mach['commit']} plus the working tree of that day, Release build; "
      f"Debian {mach['debian']}, python3-vtk9 {mach['vtk']} under `/usr/bin/python3` and `xvfb-run`, "
      f"{mach['gl_version']}; {mach['cores']} cores, {mach['cpu']}):")
    w("```sh")
    w(args.command)
    w("```")
    extra = (f"The whole command took {total} on this run up to writing this section (packages already "
             "installed, volref already built). " if total else "")
    w(f"{extra}Settings: VTK_CMP_REPS={reps}, VTK_CMP_FRAMES={frames}, VTK_CMP_THREADS=\"{settings['threads']}\", "
      f"VTK_CMP_REF_STEP={ref_step}" + (", VTK_CMP_FAST=1" if has_fast else "") +
      "; raw results (every run's JSON, the images, the references) are left in "
      f"`{args.out_label or out}`. Load average (1, 5, 15 min) at the start / end of the runs: "
      f"{settings.get('loadavg_start', '?')} / {settings.get('loadavg_end', '?')}. The machine is shared with "
      "other builds and tests, so single runs can be off by tens of percent; the interleaving spreads that "
      "load over all renderers alike, and the frame times (differences of two medians for volref) are good "
      "to about +-10-20%." + idle_note(out, settings))
    return wrap("\n".join(L)) + "\n"


def wrap(text, width=100):
    """Wraps prose lines to `width` columns like the rest of docs/performance.md; leaves tables, code
    blocks and headings alone. List items continue with two spaces."""
    out, in_code = [], False
    for line in text.split("\n"):
        if line.startswith("```"):
            in_code = not in_code
            out.append(line)
        elif in_code or line.startswith("|") or line.startswith("#") or len(line) <= width:
            out.append(line)
        else:
            bullet = line.startswith("- ")
            out.extend(textwrap.wrap(line, width=width, subsequent_indent="  " if bullet else "",
                                     break_long_words=False, break_on_hyphens=False))
    return "\n".join(out)


WHY = ("What the renderers do per sample, which is where the gap comes from. volref (this build) "
       "computes in double precision throughout: every case goes through its SIMD packet path "
       "(packets of 16 rays, Highway with run-time dispatch to the best instruction set of the CPU: "
       "4 doubles per vector with AVX2, 8 with AVX-512), the shaded case with central-difference gradients "
       "of the trilinear field on the fly (6 more trilinear fetches per sample with opacity > 0); composite "
       "rays skip empty 8^3 macrocells and MIP rays the macrocells that cannot beat their maximum so far "
       "(bitwise the same image; nothing to skip in the dense case); no early ray termination, since these "
       "scenes do not ask for it (the reference integrates every ray to its end). vtkFixedPointVolumeRayCastMapper "
       "works on 15-bit fixed-point scalars and tables, precomputes an encoded gradient per voxel and shades "
       "by table lookup per encoded normal (in the untimed warm-up frame), skips 4^3 blocks it can prove "
       "empty and stops a ray once its remaining transparency is below 255/32767 (about 1/128). The GPU mapper runs a "
       "float32 GLSL shader, compiled by llvmpipe to 256-bit vector code, and also stops at opacity "
       "1 - 1/255.")


WHY_FAST_AFTER = "(the reference integrates every ray to its end). "
WHY_FAST = ("volref's `fast` profile (render.profile \"fast\", docs/conventions.md section 9b) runs the same "
            "kernels on float lanes (8 rays per AVX2 vector, 16 per AVX-512; every case, the shaded one included, "
            "through the packet path) and stops a ray once its transmittance is at most 2^-10. ")
assert WHY_FAST_AFTER in WHY


def replace_section(doc_path, text):
    with open(doc_path) as f:
        lines = f.read().splitlines(keepends=True)
    start = next((i for i, ln in enumerate(lines) if ln.rstrip("\n") == HEADING), None)
    if start is None:
        body = "".join(lines).rstrip("\n") + "\n\n" + text
    else:
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
        tail = "".join(lines[end:])
        body = "".join(lines[:start]) + text + ("\n" + tail if tail else "")
    tmp = doc_path + ".tmp"
    with open(tmp, "w") as f:
        f.write(body)
    os.replace(tmp, doc_path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--doc", help="the markdown file whose section to replace (default: print only)")
    ap.add_argument("--command", default="bench/run_vtk_comparison.sh")
    ap.add_argument("--start", type=float, help="epoch seconds when the whole command started")
    ap.add_argument("--date", help="date to print (default: today)")
    ap.add_argument("--out-label", help="how to name OUT in the text (default: the path given)")
    args = ap.parse_args()
    text = section(args.out, args)
    with open(os.path.join(args.out, "section.md"), "w") as f:
        f.write(text)
    if args.doc:
        replace_section(args.doc, text)
        print(f"report.py: wrote the '{HEADING}' section of {args.doc}", file=sys.stderr)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
