#!/usr/bin/python3
"""Random VolPack scenes (issue 55, "on VolPack scenes you have not seen ... the same should hold"):
valid `volpack` scenes drawn from a seed, each rendered by the real VolPack 1.0b3 library and by volref
and compared byte for byte by run_case.py (tests/volpack/README.md).

    random_scenes.py VOLPACK_RENDER VOLREF OUTDIR --seed S --count N [--first K] [--jobs J] [--keep] [--large]

Case i of seed S is drawn from random.Random("volpack-random:S:i") alone, so `--seed S --first i
--count 1` redraws it. A case: 0-3 rotations (any axes; degrees uniform, or exact multiples of 90 or
45), concat left / right, sometimes a window (off-centre, non-square, near / far of either sign), an
image of 16..300 pixels a side (often smaller than the intermediate image: the warp downsamples), the
scalar table (a ramp of 2-6 points, 256 random numbers, all 0 or all 1), sometimes a gradient table,
sometimes shading (random material, > 1 sums that saturate, shininess 0.5..100, 0-6 lights or VolPack's
default light, two-sided or not), the thresholds, sometimes depth cueing, 1 or 3 channels, the
classified or raw path and sometimes VP_AXIS_OVERRIDE (an axis seen edge-on is drawn on purpose now and
then: VolPack refuses it and volref must refuse it too). The volume: the committed Marschner-Lobb
volume, brainsmall.den, or a small u8 volume drawn here (noise, blobs, constant, a ramp, a sphere, with
1- or 2-voxel-thin dims) written as a raw .nrrd next to its scene.

OUTDIR/scenes/NAME.json (+ NAME.nrrd) are the scenes; OUTDIR/work/ run_case.py's files (removed for a
passing case unless --keep); OUTDIR/failures/ each failing case: its scene (and volume), run_case.py's
output (NAME.log) and its images. One line per case, then a summary (outcomes, the % exact distribution,
pixels with error > 0, the time). Outcomes: pass; refused (VolPack refuses the scene, with an error code
or a VPBug abort such as VPDepthCueIntImage's "depth too large", and volref refuses it too: exit status
1 and an error naming a render.profile_options key); fail (run_case.py's verdict, or only one of the
two refuses). Exit status 0
when no case fails, 1 otherwise, 2 on bad usage. Run with Debian's /usr/bin/python3 (numpy, OpenImageIO).
"""
import argparse
import concurrent.futures
import contextlib
import io
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run_case  # noqa: E402

REPO = os.path.dirname(os.path.dirname(HERE))
ML_VOLUME = os.path.join(HERE, "data", "marschner-lobb-64.nrrd")
BRAIN_VOLUME = os.path.join(REPO, "reference_scenes", "data", "real", "brainsmall.den")
ML_DIMS, BRAIN_DIMS = (64, 64, 64), (128, 128, 84)


# ---------------------------------------------------------------------------------------------------
# drawing a scene
# ---------------------------------------------------------------------------------------------------

def draw_degrees(rng):
    r = rng.random()
    if r < 0.2:
        return 90 * rng.randint(-4, 4)
    if r < 0.35:
        return 45 * rng.randint(-8, 8)
    if r < 0.45:
        return rng.randint(-360, 360)
    return round(rng.uniform(-360.0, 360.0), rng.choice([1, 3, 6]))


def draw_rotations(rng):
    n = rng.choices([0, 1, 2, 3], weights=[1, 6, 7, 6])[0]
    return [[rng.choice("xyz"), draw_degrees(rng)] for _ in range(n)]


def draw_window(rng):
    cx, cy = (rng.choice([0.0, rng.uniform(-0.4, 0.4)]) for _ in range(2))
    hw = rng.uniform(0.3, 1.4)
    hh = hw if rng.random() < 0.4 else rng.uniform(0.3, 1.4)
    if rng.random() < 0.6:
        near, far = -rng.uniform(0.5, 3.0), rng.uniform(0.5, 3.0)
    else:  # anything with near < far, the volume partly or wholly outside [near, far]
        near, far = sorted(rng.uniform(-3.0, 3.0) for _ in range(2))
        far = max(far, near + 0.05)
    return [round(v, 6) for v in (cx - hw, cx + hw, cy - hh, cy + hh, near, far)]


def draw_value(rng):
    r = rng.random()
    return 0.0 if r < 0.15 else 1.0 if r < 0.3 else round(rng.random(), rng.choice([2, 6, 17]))


def draw_table(rng, max_x):
    r = rng.random()
    if r < 0.62:  # a ramp from x = 0 to max_x, 2-6 points
        n = rng.randint(2, 6)
        xs = sorted(rng.sample(range(1, max_x), n - 2)) if n > 2 else []
        return {"ramp": [[x, draw_value(rng)] for x in [0] + xs + [max_x]]}
    if r < 0.87:  # 256 numbers: uniform noise, a random walk or sparse spikes
        kind = rng.choice(["noise", "walk", "spikes"])
        if kind == "noise":
            return [round(rng.random(), 6) for _ in range(256)]
        if kind == "walk":
            v, out = rng.random(), []
            for _ in range(256):
                v = min(1.0, max(0.0, v + rng.gauss(0.0, 0.08)))
                out.append(round(v, 6))
            return out
        out = [0.0] * 256
        for x in rng.sample(range(256), rng.randint(1, 40)):
            out[x] = draw_value(rng) or 1.0
        return out
    return [0.0 if r < 0.92 else 1.0] * 256


def draw_rgb(rng, hi):
    if rng.random() < 0.5:
        return round(rng.uniform(0.0, hi), 4)
    return [round(rng.uniform(0.0, hi), 4) for _ in range(3)]


def draw_shading(rng):
    shading = {}
    if rng.random() < 0.85:
        material = {}
        hi = rng.choice([1.0, 1.0, 1.5])  # > 1 sums saturate 255
        for key in ("ambient", "diffuse", "specular"):
            if rng.random() < 0.85:
                material[key] = draw_rgb(rng, hi if key != "ambient" else 0.6)
        if rng.random() < 0.85:
            material["shininess"] = round(math.exp(rng.uniform(math.log(0.5), math.log(100.0))), 3)
        shading["material"] = material
    if rng.random() < 0.85:  # else VolPack's default light 0
        lights = []
        for _ in range(rng.choices(range(7), weights=[1, 5, 3, 2, 1, 1, 1])[0]):
            if rng.random() < 0.2:
                d = [0.0, 0.0, 0.0]
                d[rng.randrange(3)] = rng.choice([-1.0, 1.0])
            else:
                d = [0.0, 0.0, 0.0]
                while sum(v * v for v in d) < 1e-3:
                    d = [round(rng.uniform(-1.0, 1.0), 4) for _ in range(3)]
            color = [1.0, 1.0, 1.0] if rng.random() < 0.3 else [draw_value(rng) for _ in range(3)]
            lights.append({"direction": d, "color": color})
        shading["lights"] = lights
    if rng.random() < 0.5:
        shading["two_sided"] = rng.random() < 0.6
    return shading


def draw_volume(rng, outdir, name, grow=1.0):
    """(source for the scene, dims, description): a committed volume or one drawn here."""
    r = rng.random()
    if r < 0.22:
        return os.path.relpath(ML_VOLUME, outdir), ML_DIMS, "marschner-lobb-64"
    if r < 0.38:
        return os.path.relpath(BRAIN_VOLUME, outdir), BRAIN_DIMS, "brainsmall"
    nprng = np.random.default_rng(rng.getrandbits(64))
    dims = [rng.randint(5, int(40 * grow)), rng.randint(5, int(30 * grow)), rng.randint(5, int(20 * grow))]
    rng.shuffle(dims)
    thin = ""
    if rng.random() < 0.2:
        for a in rng.sample(range(3), rng.choice([1, 1, 1, 2])):
            dims[a] = rng.choice([1, 2])
        thin = ", thin"
    nx, ny, nz = dims
    z, y, x = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    kind = rng.choice(["noise", "noise", "blobs", "blobs", "blobs", "constant", "ramp", "sphere"])
    if kind == "noise":
        lo = rng.randint(0, 200)
        v = nprng.integers(lo, rng.randint(lo + 1, 256), size=(nz, ny, nx), endpoint=True)
    elif kind == "blobs":
        v = np.zeros((nz, ny, nx))
        for _ in range(rng.randint(1, 4)):
            c = [rng.uniform(0, d - 1) for d in (nx, ny, nz)]
            s = rng.uniform(1.0, max(dims) / 2.0)
            v += rng.uniform(-80, 255) * np.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) / (2 * s * s))
        v += rng.uniform(0, 60)
    elif kind == "constant":
        v = np.full((nz, ny, nx), rng.choice([0, 255, rng.randint(0, 255)]))
    elif kind == "ramp":
        a = rng.choice([x, y, z])
        v = rng.uniform(-100, 100) + a * rng.uniform(-40, 40)
    else:
        c = [(d - 1) / 2.0 + rng.uniform(-2, 2) for d in (nx, ny, nz)]
        rad = rng.uniform(1.0, max(dims) / 2.0)
        inside = (x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2 <= rad * rad
        v = np.where(inside, rng.randint(100, 255), rng.randint(0, 60))
    data = np.clip(np.rint(v), 0, 255).astype(np.uint8)
    path = os.path.join(outdir, f"{name}.nrrd")
    with open(path, "wb") as f:
        f.write(f"NRRD0004\n# random_scenes.py: {kind}\ntype: uchar\ndimension: 3\nsizes: {nx} {ny} {nz}\n"
                f"encoding: raw\n\n".encode())
        f.write(data.tobytes())
    return f"{name}.nrrd", tuple(dims), f"{kind} {nx}x{ny}x{nz}{thin}"


def draw_scene(seed, index, outdir, large=False):
    """(scene dict, name, one-line description, expect_refusal). large: images up to 800 pixels a side,
    drawn volumes up to 100 x 75 x 50."""
    rng = random.Random(f"volpack-random:{'large:' if large else ''}{seed}:{index}")
    name = f"s{seed}{'L' if large else ''}_{index:04d}"
    source, dims, vol_desc = draw_volume(rng, outdir, name, 2.5 if large else 1.0)
    big = 800 if large else 300
    side = lambda: rng.choice([rng.randint(16, big), rng.randint(16, 128)])  # noqa: E731
    width = side()
    height = width if rng.random() < 0.4 else side()
    options = {}
    rotate = draw_rotations(rng)
    if rotate or rng.random() < 0.5:
        options["rotate"] = rotate
    if rng.random() < 0.5:
        options["concat"] = rng.choice(["left", "right"])
    if rng.random() < 0.35:
        options["window"] = draw_window(rng)
    options["scalar_table"] = draw_table(rng, run_case.SCALAR_MAX)
    if rng.random() < 0.4:
        options["gradient_table"] = draw_table(rng, run_case.GRAD_MAX)
    if rng.random() < 0.6:
        options["shading"] = draw_shading(rng)
    r = rng.random()
    ties = [y for _, y in options["scalar_table"]["ramp"] if 0.0 < y <= 0.3] if isinstance(options["scalar_table"], dict) else []
    if r < 0.75:
        # -1, 0, uniform in [0, 0.3], or one of the ramp's own values (the float compare's tie)
        options["min_voxel_opacity"] = (-1 if r < 0.15 else 0 if r < 0.3 else rng.choice(ties) if ties and r < 0.4
                                        else round(rng.uniform(0.0, 0.3), 4))
    if rng.random() < 0.75:
        options["max_ray_opacity"] = 1 if rng.random() < 0.2 else round(rng.uniform(0.3001, 1.0), 4)
    if rng.random() < 0.35:
        options["depth_cue"] = {"front": round(rng.uniform(0.2, 2.0), 4), "density": round(rng.uniform(-1.0, 3.0), 4)}
    if rng.random() < 0.5:
        options["channels"] = rng.choice([1, 3])
    if rng.random() < 0.6:
        options["path"] = rng.choice(["classified", "raw"])
    expect_refusal = False
    if rng.random() < 0.2:
        # VP_AXIS_OVERRIDE: an axis VolPack takes (not nearly edge-on: the intermediate image stays small),
        # or, when the rotations are multiples of 90 degrees, possibly one seen edge-on (VolPack refuses).
        views = {a: run_case.predicted_view(dict(options, axis=a), dims, width, height) for a in "xyz"}
        right_angles = all(d % 90 == 0 for _, d in options.get("rotate", []))
        edge_on = [a for a, v in views.items() if v[1] is None]
        usable = [a for a, v in views.items() if v[1] is not None and max(v[1], v[2]) <= 4 * max(dims) + 4]
        if right_angles and edge_on and rng.random() < 0.6:
            options["axis"] = rng.choice(edge_on)
            expect_refusal = True
        elif usable:
            options["axis"] = rng.choice(usable)
    scene = {
        "description": f"random_scenes.py seed {seed} case {index}: {vol_desc}",
        "volume": {"source": source},
        "image": {"width": width, "height": height},
        "render": {"profile": "volpack", "profile_options": options},
    }
    return scene, name, summarise(vol_desc, width, height, options), expect_refusal


def summarise(vol_desc, width, height, o):
    parts = [vol_desc, f"{width}x{height}"]
    if o.get("rotate"):
        parts.append("rot " + " ".join(f"{a}{d:g}" for a, d in o["rotate"]) + (" L" if o.get("concat") == "left" else ""))
    if "window" in o:
        parts.append("window")
    st = o["scalar_table"]
    parts.append(f"ramp{len(st['ramp'])}" if isinstance(st, dict) else "list")
    if "gradient_table" in o:
        parts.append("grad")
    if "shading" in o:
        n = len(o["shading"].get("lights", [None]))
        parts.append(f"shaded/{n}L" + ("/2s" if o["shading"].get("two_sided") else ""))
    if "depth_cue" in o:
        parts.append("dc")
    parts.append(f"c{o.get('channels', 1)}")
    if o.get("path") == "raw":
        parts.append("raw")
    if "axis" in o:
        parts.append(f"axis {o['axis']}")
    return ", ".join(parts)


# ---------------------------------------------------------------------------------------------------
# running a case
# ---------------------------------------------------------------------------------------------------

SUMMARY = re.compile(r"run_case: \S+: (\d+) pixels, ([\d.]+) % exact, max diff (\d+), (\d+) outside the error "
                     r"channel \((\d+) pixels with error > 0\); view axis (\w), intermediate (\d+) x (\d+): (PASS|FAIL)")


def call_run_case(volpack_render, volref, scene_path, workdir):
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        try:
            rc = run_case.main([volpack_render, volref, scene_path, workdir])
        except SystemExit as e:  # run_case.run: a render that failed
            rc = e.code if isinstance(e.code, int) else 1
        except Exception as e:  # noqa: BLE001 (a program that cannot be run, an unreadable image): the case fails
            print(f"run_case: {type(e).__name__}: {e}")
            rc = 1
    return rc, out.getvalue()


def pixel_stats(workdir, name, channels):
    """From run_case.py's files: exact pixels, pixels with error > 0, of them exact."""
    vp = run_case.as_rgba(run_case.read_pam(os.path.join(workdir, f"{name}-volpack.pam")), channels)
    names, pixels = run_case.read_exr(os.path.join(workdir, f"{name}.exr"))
    vr = np.stack([pixels[..., names.index(c)] for c in "RGBA"], axis=-1)
    vr = np.clip(np.floor(vr * 255.0 + 0.5), 0, 255).astype(np.uint8)
    error = pixels[..., names.index("error")] > 0 if "error" in names else np.zeros(vp.shape[:2], bool)
    exact = (vp == vr).all(axis=-1)
    return {"pixels": int(exact.size), "exact": int(exact.sum()), "error": int(error.sum()),
            "error_exact": int((error & exact).sum()), "covered": int((vp[..., 3] > 0).sum())}


def run_one(volpack_render, volref, outdir, seed, index, keep, large):
    scenes, work, failures = (os.path.join(outdir, d) for d in ("scenes", "work", "failures"))
    scene, name, desc, expect_refusal = draw_scene(seed, index, scenes, large)
    scene_path = os.path.join(scenes, f"{name}.json")
    with open(scene_path, "w") as f:
        json.dump(scene, f, indent=1)
    t0 = time.time()
    rc, log = call_run_case(volpack_render, volref, scene_path, work)
    result = {"name": name, "desc": desc, "rc": rc}
    if "volpack_render failed (exit status 1)" in log:
        # VolPack refused the scene: volref must refuse it too.
        vr = subprocess.run([volref, "render", scene_path, "-o", os.path.join(work, f"{name}.exr")],
                            capture_output=True, text=True)
        # VolPack's own line: an error code's message (volpack_render: ...), or "BUG: ..." (VPBug, exit(1))
        vp_why = next((ln for ln in log.splitlines() if ln.strip() and not ln.startswith("run_case:")), "no message")
        vr_why = (vr.stderr.strip().splitlines() or [""])[-1]
        log += f"\nvolref render (VolPack refused the scene): exit status {vr.returncode}\n{vr.stdout}{vr.stderr}"
        # volref's refusal must be of the scene (an error naming render.profile_options.KEY), not any failure.
        refused = vr.returncode == 1 and "render.profile_options" in vr.stderr
        result["outcome"] = "refused" if refused else "fail"
        result["detail"] = (f"refused by VolPack ({vp_why}); volref: " +
                            (f"refused too ({vr_why})" if refused else
                             "rendered it (exit 0)" if vr.returncode == 0 else
                             f"exit status {vr.returncode} without naming a render.profile_options key ({vr_why})"))
        if not expect_refusal and result["outcome"] == "refused":
            result["detail"] += " [not drawn as a refusal]"
    else:
        m = SUMMARY.search(log)
        result["outcome"] = "pass" if rc == 0 and m else "fail"
        if m:
            result["detail"] = (f"{m.group(2)} % exact, max diff {m.group(3)}, {m.group(4)} outside, "
                                f"axis {m.group(6)} {m.group(7)}x{m.group(8)}")
            try:
                result["stats"] = pixel_stats(work, name, scene["render"]["profile_options"].get("channels", 1))
            except (OSError, ValueError, RuntimeError) as e:
                result["detail"] += f" (stats: {e})"
        else:
            lines = [ln for ln in log.strip().splitlines() if ln.strip()]
            result["detail"] = lines[-1] if lines else f"run_case exit status {rc}"
        if expect_refusal:
            result["detail"] += " [drawn as an edge-on axis override: VolPack took it]"
    result["seconds"] = time.time() - t0
    produced = [p for p in os.listdir(work) if p.startswith(name + "-") or p.startswith(name + ".")]
    if result["outcome"] == "fail":
        os.makedirs(failures, exist_ok=True)
        kept = dict(scene)
        src = scene["volume"]["source"]
        if os.path.exists(os.path.join(scenes, src)) and not os.path.isabs(src) and src.startswith(name):
            shutil.copy(os.path.join(scenes, src), os.path.join(failures, src))
        else:
            kept["volume"] = {"source": os.path.relpath(os.path.normpath(os.path.join(scenes, src)), failures)}
        with open(os.path.join(failures, f"{name}.json"), "w") as f:
            json.dump(kept, f, indent=1)
        with open(os.path.join(failures, f"{name}.log"), "w") as f:
            f.write(f"{desc}\n{result['detail']}\n\n{log}")
        for p in produced:
            if not p.endswith(".u8"):
                shutil.move(os.path.join(work, p), os.path.join(failures, p))
    if not keep:
        for p in produced:
            path = os.path.join(work, p)
            if os.path.exists(path):
                os.remove(path)
    return result


# ---------------------------------------------------------------------------------------------------
# main
# ---------------------------------------------------------------------------------------------------

def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * (len(values) - 1) + 0.5))] if values else float("nan")


def main(argv):
    ap = argparse.ArgumentParser(description="Random VolPack scenes against the real library (tests/volpack).")
    ap.add_argument("volpack_render")
    ap.add_argument("volref")
    ap.add_argument("outdir")
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--count", type=int, required=True)
    ap.add_argument("--first", type=int, default=0, help="the first case's index (default 0)")
    ap.add_argument("--jobs", type=int, default=1, help="cases run at once (default 1)")
    ap.add_argument("--keep", action="store_true", help="keep run_case.py's files of passing cases")
    ap.add_argument("--large", action="store_true",
                    help="larger cases (images up to 800 pixels a side, drawn volumes up to 100 x 75 x 50); "
                         "another draw: its cases are named sSL_i")
    args = ap.parse_args(argv)
    if args.count < 1 or args.jobs < 1 or args.first < 0:
        ap.error("--count and --jobs must be >= 1, --first >= 0")
    for path in (ML_VOLUME, BRAIN_VOLUME):
        if not os.path.exists(path):
            print(f"random_scenes: {path}: no such file"
                  + (" (run scripts/fetch-reference-data.sh)" if "data/real" in path else ""), file=sys.stderr)
            return 2
    outdir = os.path.abspath(args.outdir)
    for d in ("scenes", "work"):
        os.makedirs(os.path.join(outdir, d), exist_ok=True)
    shutil.rmtree(os.path.join(outdir, "failures"), ignore_errors=True)
    volpack_render, volref = os.path.abspath(args.volpack_render), os.path.abspath(args.volref)
    indices = range(args.first, args.first + args.count)
    t0 = time.time()
    results = []
    with concurrent.futures.ProcessPoolExecutor(args.jobs) if args.jobs > 1 else contextlib.nullcontext() as pool:
        if pool:
            futures = [pool.submit(run_one, volpack_render, volref, outdir, args.seed, i, args.keep, args.large) for i in indices]
            iterator = (f.result() for f in futures)
        else:
            iterator = (run_one(volpack_render, volref, outdir, args.seed, i, args.keep, args.large) for i in indices)
        for r in iterator:
            results.append(r)
            print(f"{r['name']}: {r['outcome'].upper()}: {r['detail']} ({r['desc']}; {r['seconds']:.1f} s)", flush=True)
    elapsed = time.time() - t0

    counts = {k: sum(r["outcome"] == k for r in results) for k in ("pass", "refused", "fail")}
    stats = [r["stats"] for r in results if "stats" in r]
    exact = [100.0 * s["exact"] / s["pixels"] for s in stats]
    total = {k: sum(s[k] for s in stats) for k in ("pixels", "exact", "error", "error_exact", "covered")}
    print(f"random_scenes: seed {args.seed}{' (large)' if args.large else ''}, cases {args.first}..{args.first + args.count - 1}: "
          f"{counts['pass']} pass, {counts['refused']} refused by VolPack (and by volref), {counts['fail']} fail; "
          f"{elapsed:.1f} s")
    if exact:
        print(f"random_scenes: % exact over {len(exact)} compared cases: min {min(exact):.3f}, "
              f"1st pct {percentile(exact, 0.01):.3f}, median {percentile(exact, 0.5):.3f}; "
              f"{sum(e == 100.0 for e in exact)} at 100 %, {sum(99.9 <= e < 100.0 for e in exact)} in [99.9, 100), "
              f"{sum(e < 99.9 for e in exact)} below 99.9")
        print(f"random_scenes: pixels: {total['pixels']} ({total['covered']} with VolPack alpha > 0), "
              f"{total['pixels'] - total['exact']} not exact; {total['error']} with error > 0, "
              f"{total['error_exact']} of them exact anyway")
    for r in results:
        if r["outcome"] == "fail":
            print(f"random_scenes: FAIL {r['name']}: {r['detail']} (kept in {os.path.join(outdir, 'failures')})")
    return 1 if counts["fail"] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
