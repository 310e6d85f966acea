#!/usr/bin/python3
"""VolPack's error, measured (issue 55, item 4): VolPack 1.0b3's images of the benchmark scenes
(bench/volpack/*.json, volpack scenes) against volref's reference of the continuous scene each one
discretises (`volref explain volpack-scene`), and the times of VolPack, of volref's volpack profile, of the
reference and of the fast profile at the step where its error equals VolPack's. Writes the section
"## VolPack: its error against the reference, and its speed" (OUTDIR/section.md, and into
docs/performance.md with --doc). Run through bench/volpack_error.sh.

    volpack_error.py OUTDIR [--doc DOC] [--reps N] [--frames N] [--threads "1 2"] [--tolerance T]
                     [--fast-steps "S ..."] [--scenes "NAME ..."] [--command CMD]

Per scene, first the accuracy renders (each once, at the largest thread count):
  - VolPack: tests/volpack/volpack_render (Debian's libvolpack), the scene translated by
    tests/volpack/run_case.py's volpack_args; its PAM buffer is the image (k / 255, premultiplied).
  - volref's volpack profile (`volref render SCENE`): must give VolPack's bytes (run_case.py's rule: equal,
    or off by one where the EXR's error channel is > 0).
  - the continuous scene (`volref explain volpack-scene --scene SCENE --step 0.125`), rendered by the
    reference profile at step 1/8 voxel (THE reference of this page), at 1/16 voxel and with the adaptive
    integrator (render.tolerance T, default 1e-4); also, for the error's causes, pre-classified
    (volume.classify "pre") at 1/8 voxel on the grid and on the grid padded by one voxel of zeros (origin
    -1: the pre-classified opacity then fades over the voxel past the grid's last as VolPack's does), and
    the fast profile (render.profile "fast") at each of the fast steps.
  The continuous scene as explain prints it lists volref's default headlight before VolPack's lights
  (volpack_continuous_scene appends to Scene::lights, whose default is one headlight): for a shaded scene
  that extra light is removed here (reported as "headlight_removed"; a no-op once explain is fixed).
Images are compared as premultiplied RGBA in [0, 1] (VolPack: bytes / 255, luminance in R, G and B; volref
renders the continuous scene in white, so R = G = B): RMSE over all pixels and channels (background
included, as the VTK comparison counts it), the largest absolute difference, and over the pixels where
either image has alpha >= 0.5 / 255 ("covered") the 99th percentile of a pixel's largest channel
difference and the % of them above 2 / 255. "halo": the pixels whose ray misses the grid's domain (voxel
centres [0, n - 1]^3) but meets (-1, n)^3, where only VolPack's fading opacity is (slab tests with the
continuous scene's camera).

Then the timing rounds (--reps, default 3), interleaved: in each round, for each scene, VolPack once
(`volpack_render --time --repeat F`: the render call alone, median of F frames, one thread: VolPack has no
threads) and for each thread count the volpack profile (`volref render --timing --repeat F`), the
reference at 1/8 (`--timing`, one frame) and the fast profile at its equal-RMSE step (`--repeat F`).
Reported: medians over the rounds of each run's median frame. volref's --timing frame is what follows its
set-up; for the volpack profile the set-up (setup_s) holds the classification, shading and compositing of
the intermediate image, the frame the 2-D warp alone, so both are given and their sum is the number to set
beside VolPack's render call (which also composites and warps; its vpVolumeNormals and vpClassifyVolume
are given separately, as VolPack's own set-up).
"""
import argparse
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "volpack"))
import run_case as rc  # noqa: E402  (volpack_args, read_u8_volume, read_pam, read_exr, compare)

HEADING = "## VolPack: its error against the reference, and its speed"
AFTER_HEADING = "## volref beside VTK"  # a new section goes after this one
SCENES = ["ml256_unshaded", "ml256_shaded", "ml64_unshaded", "ml64_shaded", "brain_unshaded_thresholds",
          "brain_unshaded_nothresholds", "brain_shaded_thresholds", "brain_shaded_nothresholds"]
ML256 = os.path.join(ROOT, "build", "volpack-bench", "marschner-lobb-256.nrrd")
TWO = 2.0 / 255.0


def log(msg):
    print(f"{time.strftime('%H:%M:%S')} [volpack-error] {msg}", file=sys.stderr, flush=True)


def run(cmd, what):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout + r.stderr)
        raise SystemExit(f"volpack_error: {what} failed (exit status {r.returncode}): {' '.join(cmd)}")
    return r


def timing_line(stderr, prefix):
    m = re.search(prefix + r": timing (\{.*\})", stderr)
    if not m:
        raise SystemExit(f"volpack_error: no timing line from {prefix}: {stderr.strip()}")
    return json.loads(m.group(1))


# ---------------------------------------------------------------------------------------------------
# images and their differences
# ---------------------------------------------------------------------------------------------------

def read_exr_rgba(path):
    names, px = rc.read_exr(path)
    rgba = np.stack([px[..., names.index(c)] for c in "RGBA"], axis=-1)
    err = px[..., names.index("error")] if "error" in names else None
    return rgba, err


def read_volpack(path):
    vp = rc.read_pam(path)
    return rc.as_rgba(vp, 1 if vp.shape[2] == 2 else 3).astype(np.float64) / 255.0


def stats(a, b, mask=None):
    d = np.abs(a - b)
    per_pixel = d.max(axis=-1)
    covered = np.maximum(a[..., 3], b[..., 3]) >= 0.5 / 255.0
    cov = per_pixel[covered]
    s = {"rmse": float(np.sqrt(np.mean(d * d))), "max": float(d.max()),
         "rmse_rgb": float(np.sqrt(np.mean(d[..., :3] ** 2))), "max_rgb": float(d[..., :3].max()),
         "p99": float(np.percentile(cov, 99)) if cov.size else 0.0,
         "over2": float(100.0 * np.mean(cov > TWO)) if cov.size else 0.0,
         "covered": int(covered.sum())}
    if mask is not None:
        sq = (d * d).sum(axis=-1)
        total = float(sq.sum())
        s["halo_pixels"] = int(mask.sum())
        s["halo_share"] = float(sq[mask].sum() / total) if total > 0 else 0.0
        s["rmse_outside_halo"] = float(np.sqrt(sq[~mask].sum() / (4.0 * sq.size)))
    return s


def box_interval(camera, width, height, lo, hi):
    """Per pixel, the ray's parameter interval inside the box [lo, hi] (index = world: origin 0, spacing
    1, as the benchmark volumes are): the camera's view rows are (X, Y, depth) with pixel (x, y) at X = x,
    Y = y (column-major view matrix)."""
    view = np.array(camera["view"], dtype=np.float64).reshape(4, 4).T
    a_inv = np.linalg.inv(view[:3, :3])
    d = a_inv @ np.array([0.0, 0.0, 1.0])
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float64)
    p0 = (np.stack([xs, ys, np.zeros_like(xs)], axis=-1) - view[:3, 3]) @ a_inv.T
    t0 = np.full((height, width), -np.inf)
    t1 = np.full((height, width), np.inf)
    for k in range(3):
        if abs(d[k]) < 1e-300:
            outside = (p0[..., k] < lo[k]) | (p0[..., k] > hi[k])
            t0 = np.where(outside, np.inf, t0)
            continue
        u, v = (lo[k] - p0[..., k]) / d[k], (hi[k] - p0[..., k]) / d[k]
        t0, t1 = np.maximum(t0, np.minimum(u, v)), np.minimum(t1, np.maximum(u, v))
    return t0, t1


# ---------------------------------------------------------------------------------------------------
# one scene's renders
# ---------------------------------------------------------------------------------------------------

class Tools:
    def __init__(self, build):
        self.volref = os.path.join(build, "cli", "volref")
        self.volpack_render = os.path.join(build, "tests", "volpack", "volpack_render")
        for p in (self.volref, self.volpack_render):
            if not os.access(p, os.X_OK):
                raise SystemExit(f"volpack_error: {p} is missing (cmake --build {build} --target volref_cli volpack_render)")

    def volpack(self, args, out, frames):
        r = run([self.volpack_render, *args, "--output", out, "--time", "--repeat", str(frames)], "volpack_render")
        return timing_line(r.stderr, "volpack_render")

    def render(self, scene, out, threads, sets=(), repeat=1):
        cmd = [self.volref, "render", scene, "-o", out, "--threads", str(threads), "--timing"]
        if repeat > 1:
            cmd += ["--repeat", str(repeat)]
        for s in sets:
            cmd += ["--set", s]
        return timing_line(run(cmd, "volref render").stderr, "volref")


def fast_sets(step):
    return ["render.profile=fast", f"render.step={step!r}"]


def prepare_scene(tools, name, work, tolerance, fast_steps, threads):
    """The accuracy renders and their comparisons; returns the scene's record."""
    scene = os.path.join(ROOT, "bench", "volpack", name + ".json")
    os.makedirs(work, exist_ok=True)
    with open(scene) as f:
        spec = json.load(f)
    options = spec["render"]["profile_options"]
    rec = {"name": name, "width": spec["image"]["width"], "height": spec["image"]["height"],
           "shaded": "shading" in options, "two_sided": bool(options.get("shading", {}).get("two_sided", False)),
           "min_voxel_opacity": options.get("min_voxel_opacity"), "max_ray_opacity": options.get("max_ray_opacity")}
    rec["one_sided"] = rec["shaded"] and not rec["two_sided"]
    args, info = rc.volpack_args(scene, work, name)
    rec["dims"] = info["dims"]
    rec["args"] = args
    img = {}

    # VolPack, and volref's volpack profile: the same bytes.
    vp_pam = os.path.join(work, "volpack.pam")
    tools.volpack(args, vp_pam, 1)
    img["volpack"] = read_volpack(vp_pam)
    tools.render(scene, os.path.join(work, "volpack-profile.exr"), threads)
    vr, err = read_exr_rgba(os.path.join(work, "volpack-profile.exr"))
    vr8 = np.clip(np.floor(vr * 255.0 + 0.5), 0, 255).astype(np.uint8)
    vp8 = np.clip(np.rint(img["volpack"] * 255.0), 0, 255).astype(np.uint8)
    passed, summary, _ = rc.compare(vp8, vr8, err if err is not None else np.zeros(vr.shape[:2]))
    rec["profile_bytes"] = {"passed": bool(passed), "exact": summary["exact"], "max_diff": summary["max_diff"]}
    log(f"{name}: volpack profile against VolPack: {100 * summary['exact']:.3f} % exact, max diff "
        f"{summary['max_diff']}: {'PASS' if passed else 'FAIL'}")

    # The continuous scene.
    cont = run([tools.volref, "explain", "volpack-scene", "--scene", scene, "--step", "0.125"], "volref explain").stdout
    cont = json.loads(cont)
    vp_lights = len(options["shading"].get("lights", [None])) if rec["shaded"] else 0
    lights = cont.get("lights", [])
    rec["headlight_removed"] = False
    if rec["shaded"] and len(lights) == vp_lights + 1 and lights[0].get("type") == "headlight":
        cont["lights"] = lights[1:]
        rec["headlight_removed"] = True
    cont_path = os.path.join(work, "continuous.json")
    with open(cont_path, "w") as f:
        json.dump(cont, f, indent=1)

    renders = {"ref8": ["render.step=0.125"], "ref16": ["render.step=0.0625"],
               "adaptive": ["render.integrator=adaptive", f"render.tolerance={tolerance!r}"],
               "pre8": ["render.step=0.125", "volume.classify=pre"]}
    rec["render_s"] = {}
    for key, sets in renders.items():
        t = tools.render(cont_path, os.path.join(work, key + ".exr"), threads, sets)
        rec["render_s"][key] = t["median_s"]
        img[key], e = read_exr_rgba(os.path.join(work, key + ".exr"))
        if key == "adaptive":
            rec["adaptive_error_max"] = float(e.max()) if e is not None else None
        log(f"{name}: {key} {t['median_s']:.2f} s")

    # Pre-classified on the grid padded with one voxel of zeros at origin -1: VolPack's fade. Only where
    # neither the classification nor the colour reads the gradient: the zeros would change the boundary
    # voxels' gradients (VolPack gives them gradient 0 and normal code 0 instead).
    dims, voxels = rc.read_u8_volume(cont["volume"]["source"]["file"], work)
    rec["fade_measured"] = not rec["shaded"] and "gradient_table" not in options
    nx, ny, nz = dims
    if rec["fade_measured"]:
        pad = np.zeros((nz + 2, ny + 2, nx + 2), np.uint8)
        pad[1:-1, 1:-1, 1:-1] = np.frombuffer(voxels, np.uint8).reshape(nz, ny, nx)
        pad_path = os.path.join(work, "padded.nrrd")
        with open(pad_path, "wb") as f:
            f.write(f"NRRD0004\ntype: uchar\ndimension: 3\nsizes: {nx + 2} {ny + 2} {nz + 2}\nencoding: raw\n\n".encode())
            f.write(pad.tobytes())
        padded = json.loads(json.dumps(cont))
        padded["volume"]["source"] = {"file": pad_path}
        padded["volume"]["origin"] = [-1.0, -1.0, -1.0]
        padded_path = os.path.join(work, "continuous-padded.json")
        with open(padded_path, "w") as f:
            json.dump(padded, f, indent=1)
        tools.render(padded_path, os.path.join(work, "pre8pad.exr"), threads, renders["pre8"])
        img["pre8pad"], _ = read_exr_rgba(os.path.join(work, "pre8pad.exr"))

    # The halo, and the comparisons.
    t0, t1 = box_interval(cont["camera"], rec["width"], rec["height"], [0, 0, 0], [n - 1 for n in dims])
    g0, g1 = box_interval(cont["camera"], rec["width"], rec["height"], [-1, -1, -1], list(dims))
    halo = (g1 > g0) & ~(t1 > t0)
    ref = img["ref8"]
    s0, s1 = box_interval(cont["camera"], rec["width"], rec["height"], [1, 1, 1], [n - 2 for n in dims])
    rim = (g1 > g0) & ~(s1 > s0)  # rays within one voxel of the grid's faces all along: the silhouette's rim
    rec["rim"] = stats(img["volpack"], ref, rim)
    rec["volpack_vs_ref8"] = stats(img["volpack"], ref, halo)
    rec["volpack_vs_adaptive"] = stats(img["volpack"], img["adaptive"])
    rec["ref8_vs_ref16"] = stats(ref, img["ref16"])
    rec["ref8_vs_adaptive"] = stats(ref, img["adaptive"])
    rec["ref16_vs_adaptive"] = stats(img["ref16"], img["adaptive"])
    rec["pre8_vs_ref8"] = stats(img["pre8"], ref)
    if rec["fade_measured"]:
        rec["pre8pad_vs_pre8"] = stats(img["pre8pad"], img["pre8"], halo)
        rec["pre8pad_vs_ref8"] = stats(img["pre8pad"], ref, halo)
        rec["volpack_vs_pre8pad"] = stats(img["volpack"], img["pre8pad"], halo)
    rec["trunc8_vs_ref8"] = stats(np.floor(ref * 255.0) / 255.0, ref)
    rec["round8_vs_ref8"] = stats(np.clip(np.floor(ref * 255.0 + 0.5), 0, 255) / 255.0, ref)
    np.save(os.path.join(work, "volpack-error.npy"), np.abs(img["volpack"] - ref).max(axis=-1).astype(np.float32))

    # The fast profile against its step.
    rec["fast"] = []
    for step in fast_steps:
        out = os.path.join(work, f"fast-{step:g}.exr")
        t = tools.render(cont_path, out, threads, fast_sets(step))
        fimg, _ = read_exr_rgba(out)
        s = stats(fimg, ref)
        rec["fast"].append({"step": step, "rmse": s["rmse"], "max": s["max"], "rmse_rgb": s["rmse_rgb"],
                            "max_rgb": s["max_rgb"], "frame_s": t["median_s"]})
    target = rec["volpack_vs_ref8"]["rmse"]
    ok = [f for f in rec["fast"] if f["rmse"] <= target]
    rec["fast_equal"] = max(ok, key=lambda f: f["step"]) if ok else None
    rec["fast_all_below"] = all(f["rmse"] <= target for f in rec["fast"])
    log(f"{name}: VolPack RMSE {target:.5f}; fast at equal RMSE: "
        f"{'step %g (%.5f)' % (rec['fast_equal']['step'], rec['fast_equal']['rmse']) if ok else 'none'}")
    return rec, img


def cpu_idle(seconds=0.5):
    def sample():
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        return v[3] + v[4], sum(v)
    i0, t0 = sample()
    time.sleep(seconds)
    i1, t1 = sample()
    return (i1 - i0) / max(1, t1 - t0)


WAIT = {"runs": 0, "idle": 0, "waited_s": 0.0, "budget_s": 300.0}


def wait_idle():
    """Before a timed run: wait until the CPUs were >= 90 % idle over half a second (at most 20 s per run,
    300 s in all), as bench/vtk/driver.sh does."""
    WAIT["runs"] += 1
    start = time.time()
    while True:
        if cpu_idle() >= 0.9:
            WAIT["idle"] += 1
            break
        if time.time() - start > 20 or WAIT["waited_s"] + time.time() - start > WAIT["budget_s"]:
            break
    WAIT["waited_s"] += time.time() - start


def time_rounds(tools, recs, reps, frames, thread_counts, out):
    """The interleaved timing rounds: fills rec["times"]."""
    for rec in recs:
        rec["times"] = {"volpack": [], "volpack_normals": [], "volpack_classify": [], "volpack_shade": []}
        for t in thread_counts:
            rec["times"].update({f"profile_frame_{t}": [], f"profile_setup_{t}": [], f"ref8_{t}": [], f"fast_{t}": []})
    images_same = True
    for r in range(reps):
        log(f"timing round {r + 1} of {reps}")
        for rec in recs:
            name, work = rec["name"], os.path.join(out, rec["name"])
            scene = os.path.join(ROOT, "bench", "volpack", name + ".json")
            wait_idle()
            v = tools.volpack(rec["args"], os.path.join(work, "volpack-timed.pam"), frames)
            rec["times"]["volpack"].append(v["median_s"])
            rec["times"]["volpack_normals"].append(v["normals_s"])
            rec["times"]["volpack_classify"].append(v["classify_s"])
            rec["times"]["volpack_shade"].append(statistics.median(v["shade_s"]) if v["shade_s"] else 0.0)
            cont = os.path.join(work, "continuous.json")
            for t in thread_counts:
                wait_idle()
                p = tools.render(scene, os.path.join(work, f"volpack-profile-{t}.exr"), t, repeat=frames)
                rec["times"][f"profile_frame_{t}"].append(p["median_s"])
                rec["times"][f"profile_setup_{t}"].append(p["setup_s"])
                wait_idle()
                q = tools.render(cont, os.path.join(work, f"ref8-{t}.exr"), t, ["render.step=0.125"])
                rec["times"][f"ref8_{t}"].append(q["median_s"])
                if rec["fast_equal"]:
                    wait_idle()
                    f = tools.render(cont, os.path.join(work, f"fast-eq-{t}.exr"), t, fast_sets(rec["fast_equal"]["step"]),
                                     repeat=frames)
                    rec["times"][f"fast_{t}"].append(f["median_s"])
        for rec in recs:  # every thread count gives the same image
            work = os.path.join(out, rec["name"])
            base = {"volpack-profile": read_exr_rgba(os.path.join(work, "volpack-profile.exr"))[0],
                    "ref8": read_exr_rgba(os.path.join(work, "ref8.exr"))[0]}
            for t in thread_counts:
                for key in base:
                    if not np.array_equal(read_exr_rgba(os.path.join(work, f"{key}-{t}.exr"))[0], base[key]):
                        images_same = False
                        log(f"{rec['name']}: {key} at {t} thread(s) differs from the accuracy render")
    for rec in recs:
        rec["median"] = {k: (statistics.median(v) if v else None) for k, v in rec["times"].items()}
    return images_same


# ---------------------------------------------------------------------------------------------------
# the section
# ---------------------------------------------------------------------------------------------------

def ms(s):
    if s is None:
        return "-"
    return f"{1000 * s:.1f}" if s < 0.1 else f"{1000 * s:.0f}"


def sec(s):
    return f"{s:.1f} s" if s < 100 else f"{s:.0f} s"


def e(x):
    if x == 0:
        return "0"
    return f"{x:.4f}" if x >= 1e-3 else f"{x:.1e}"


LABELS = {
    "ml256_unshaded": "ML 256^3, 512^2, unshaded (tent)",
    "ml256_shaded": "ML 256^3, 512^2, shaded two-sided (tent)",
    "ml64_unshaded": "ML 64^3, 256^2, unshaded (ramp)",
    "ml64_shaded": "ML 64^3, 256^2, shaded two-sided (surface)",
    "brain_unshaded_thresholds": "brainsmall, unshaded, min 0.05 / max 0.95",
    "brain_unshaded_nothresholds": "brainsmall, unshaded, min 0 / max 1",
    "brain_shaded_thresholds": "brainsmall, shaded two-sided, min 0.05 / max 0.95",
    "brain_shaded_nothresholds": "brainsmall, shaded two-sided, min 0 / max 1",
}


def section(recs, meta):
    T = meta["threads"]
    L = [HEADING, "",
         "*Written by `bench/volpack_error.sh` (bench/volpack/volpack_error.py); rerunning the command replaces this section.*", ""]
    L.append(
        "VolPack 1.0b3 (Debian's libvolpack1-dev, through tests/volpack/volpack_render) on the scenes of "
        "`bench/volpack/*.json` against volref's reference of the continuous scene each one discretises "
        "(`volref explain volpack-scene`: the same volume and pixels, the scalar table as opacity rows with unit "
        "distance one voxel, the gradient table as gradient opacity, white, VolPack's material and light as "
        "Blinn-Phong; post-classified, trilinear). The reference is the reference profile at step 1/8 voxel; its "
        f"convergence is checked against step 1/16 and the adaptive integrator (render.tolerance {meta['tolerance']:g}). "
        "ML = Marschner-Lobb (fm 6, alpha 0.25) quantised to u8 as round(255 rho) (`bench/volpack/make_ml_u8.py`, "
        "written to `build/volpack-bench/` for 256^3; 64^3 is tests/volpack/data); the tent is "
        "bench/vtk/scenes/composite.json's (0 at 112, 0.16 per voxel = 0.5 per 4 voxels at 128, 0 at 143); "
        "brainsmall is VolPack's examples' set-up (ramps, rotations, material, light) without depth cue. All views "
        "are rotated off the axes (the ML 256^3 view is y -60 then x 25: VTK's azimuth and elevation). Every "
        "shaded scene is two-sided, where the continuous scene is exact (one-sided would be flagged: VolPack "
        "turns a surface towards the viewer, volref's one-sided rule does not).")
    L.append("")
    L.append("Images: premultiplied RGBA in [0, 1] (VolPack's bytes / 255; luminance in R, G, B). RMSE over all "
             "pixels and channels, background included (as the VTK comparison counts); max: the largest "
             "absolute difference; p99 and > 2/255: over the covered pixels (alpha >= 0.5/255 in either image), of a "
             "pixel's largest channel difference. volref's volpack profile gave VolPack's bytes on every scene "
             "(column \"bytes\").")
    L.append("")
    L.append("| scene | VolPack vs reference: RMSE / max / p99 / > 2/255 | vs adaptive: RMSE | reference 1/8 vs 1/16: RMSE / max | 1/8 vs adaptive: RMSE / max | bytes = VolPack | VolPack frame | VolPack normals + classify | volpack profile set-up + frame, " + " / ".join(f"{t} thr" for t in T) + " | reference 1/8, " + " / ".join(f"{t} thr" for t in T) + " | fast at equal RMSE: step (RMSE) | fast frame, " + " / ".join(f"{t} thr" for t in T) + " | fast / VolPack frame, " + " / ".join(f"{t} thr" for t in T) + " |")
    L.append("|" + "---|" * (L[-1].count(" | ") + 1))
    for r in recs:
        m = r["median"]
        v = r["volpack_vs_ref8"]
        flag = " (one-sided: flagged)" if r["one_sided"] else ""
        prof = " / ".join(f"{ms(m[f'profile_setup_{t}'])} + {ms(m[f'profile_frame_{t}'])}" for t in T)
        refs = " / ".join(sec(m[f"ref8_{t}"]) for t in T)
        if r["fast_equal"]:
            nxt = next((f for f in r["fast"] if f["step"] > r["fast_equal"]["step"]), None)
            fe = (f"{r['fast_equal']['step']:g} ({e(r['fast_equal']['rmse'])}; "
                  + (f"{nxt['step']:g}: {e(nxt['rmse'])})" if nxt else "the largest tried)"))
            ff = " / ".join(ms(m[f"fast_{t}"]) for t in T)
            ratio = " / ".join(f"{m[f'fast_{t}'] / m['volpack']:.1f}x" for t in T)
        else:
            fe, ff, ratio = f"none (step {r['fast'][0]['step']:g}: {e(r['fast'][0]['rmse'])})", "-", "-"
        b = r["profile_bytes"]
        L.append(f"| {LABELS.get(r['name'], r['name'])}{flag} | {e(v['rmse'])} / {e(v['max'])} / {e(v['p99'])} / {v['over2']:.1f} % "
                 f"| {e(r['volpack_vs_adaptive']['rmse'])} "
                 f"| {e(r['ref8_vs_ref16']['rmse'])} / {e(r['ref8_vs_ref16']['max'])} "
                 f"| {e(r['ref8_vs_adaptive']['rmse'])} / {e(r['ref8_vs_adaptive']['max'])} "
                 f"| {'yes' if b['passed'] and b['exact'] == 1.0 else ('within the error channel' if b['passed'] else 'NO')} "
                 f"| {ms(m['volpack'])} ms | {ms(m['volpack_normals'])} + {ms(m['volpack_classify'])} ms "
                 f"| {prof} ms | {refs} | {fe} | {ff} ms | {ratio} |")
    L.append("")
    L.append("Times: medians over the rounds of each run's median frame (VolPack and the volpack and fast profiles: "
             f"{meta['frames']} frames per run; the reference: one frame per run). *VolPack frame*: "
             "vpRenderClassifiedVolume alone (vpShadeTable, 0.2 ms, not included); *normals + classify*: "
             "vpVolumeNormals and vpClassifyVolume, VolPack's set-up, once per volume and table. *volpack profile*: "
             "`volref render --timing`'s setup_s (reading the volume, the 8-bit gradients and normal codes, classification, "
             "shading and the intermediate image's compositing: VolPackRenderer is built there) + its frame (the 2-D "
             "warp alone). *fast at equal RMSE*: the largest step of the fast profile (render.profile \"fast\") on "
             "the continuous scene whose RMSE against the reference is at most VolPack's, and in brackets its RMSE and the next step's (steps tried: "
             + ", ".join(f"{s:g}" for s in meta["fast_steps"]) + " voxel); its frame against VolPack's frame "
             "(> 1: VolPack is faster).")
    L.append("")

    # Reading it.
    vr = [r["volpack_vs_ref8"]["rmse"] for r in recs]
    conv = [r["volpack_vs_ref8"]["rmse"] / max(r["ref8_vs_adaptive"]["rmse"], r["ref8_vs_ref16"]["rmse"], 1e-300) for r in recs]
    L.append("Reading it:")
    L.append(f"- VolPack's RMSE against the reference is {min(vr):.4f} to {max(vr):.4f}; the reference's own distance to "
             f"step 1/16 and to the adaptive image is {min(conv):.0f}x to {max(conv):.0f}x smaller, so the numbers are "
             "VolPack's (the largest reference differences, up to "
             f"{max(r['ref8_vs_adaptive']['max'] for r in recs):.2f}, are a few pixels of brainsmall's shaded surface, where the "
             "opacity reaches 1 from value 24 on: the colour is the shading where the ray turns opaque, which a fixed step "
             "places to within a step and which converges with order 1 only).")
    for t in T:
        rs = [r["median"][f"fast_{t}"] / r["median"]["volpack"] for r in recs if r["fast_equal"] and r["median"].get(f"fast_{t}")]
        if rs:
            L.append(f"- At equal RMSE the fast profile's frame is {min(rs):.1f}x to {max(rs):.1f}x VolPack's at {t} thread(s).")
    for t in T:
        rs = [(r["median"][f"profile_setup_{t}"] + r["median"][f"profile_frame_{t}"])
              / (r["median"]["volpack_normals"] + r["median"]["volpack_classify"] + r["median"]["volpack"]) for r in recs]
        L.append(f"- The volpack profile (set-up + frame) takes {min(rs):.1f}x to {max(rs):.1f}x VolPack's normals + classify + "
                 f"frame at {t} thread(s) (its set-up also reads the volume file).")
    L.append("")

    # Where the error is.
    L.append("**Where VolPack's error is.** The continuous scene's image changed one discretisation at a time, "
             "each step's RMSE (all against the one before; the last column is what is left between VolPack and the "
             "pre-classified, faded continuous image: its slices, the in-slice bilinear samples at VolPack's step L, "
             "the per-voxel opacity correction and 8-bit opacities, the thresholds, the normal codes, the 2-D warp and "
             "the truncated output bytes). *pre*: the reference with volume.classify \"pre\" (each voxel classified "
             "and shaded, then interpolated), step 1/8; *fade*: the same on the grid padded with one voxel of zeros "
             "(its opacity then falls to 0 over the voxel past the grid's last, as VolPack's does); *halo*: the "
             "pixels whose rays miss the grid's domain but pass within one voxel of it (only VolPack's fading "
             "opacity reaches them), their share of VolPack's squared error; *rim*: the pixels whose rays stay within one "
             "voxel of the grid's faces all along (they meet (-1, n)^3 but not [1, n - 2]^3: the silhouette's edge, halo "
             "included). The fade is measured only on the unshaded scenes without a gradient table (\"-\" elsewhere): "
             "the padding zeros would change the boundary voxels' gradients, which VolPack sets to 0 (gradient 0, normal "
             "code 0: with a gradient table VolPack's boundary voxels are transparent). 8-bit floor: the reference "
             "truncated to bytes (VolPack truncates) / rounded.")
    L.append("")
    L.append("| scene | VolPack vs reference | post -> pre | pre -> pre + fade | pre + fade -> VolPack | halo: pixels, share of VolPack's squared error | rim: pixels, share | VolPack RMSE outside the rim | 8-bit floor, truncated / rounded |")
    L.append("|---|---|---|---|---|---|---|---|---|")
    for r in recs:
        v, rim = r["volpack_vs_ref8"], r["rim"]
        fade = (f"{e(r['pre8pad_vs_pre8']['rmse'])} | {e(r['volpack_vs_pre8pad']['rmse'])}" if r["fade_measured"] else "- | -")
        L.append(f"| {LABELS.get(r['name'], r['name'])} | {e(v['rmse'])} | {e(r['pre8_vs_ref8']['rmse'])} "
                 f"| {fade} | {v['halo_pixels']}, {100 * v['halo_share']:.1f} % "
                 f"| {rim['halo_pixels']}, {100 * rim['halo_share']:.1f} % | {e(rim['rmse_outside_halo'])} "
                 f"| {e(r['trunc8_vs_ref8']['rmse'])} / {e(r['round8_vs_ref8']['rmse'])} |")
    L.append("")
    by = {r["name"]: r for r in recs}
    for kind in ("unshaded", "shaded"):
        a, b = by.get(f"brain_{kind}_thresholds"), by.get(f"brain_{kind}_nothresholds")
        if a and b:
            L.append(f"- Thresholds, brainsmall {kind}: VolPack's RMSE {e(a['volpack_vs_ref8']['rmse'])} with min 0.05 / max 0.95, "
                     f"{e(b['volpack_vs_ref8']['rmse'])} with min 0 / max 1 (the continuous scene is the same).")
    removed = [r["name"] for r in recs if r["headlight_removed"]]
    if removed:
        L.append(f"- `volref explain volpack-scene` listed volref's default headlight before VolPack's light on the shaded "
                 f"scenes ({', '.join(removed)}); the script removed it (volpack_continuous_scene appends VolPack's lights to "
                 "Scene::lights, whose default is one headlight; rendered as printed, brainsmall shaded is 0.28 RMSE off).")
    L.append("")

    # Beside VTK, in the form of "volref beside VTK"'s error table.
    L.append("**Beside VTK**, in the form of the error table of \"volref beside VTK\" (RGB over black: RMSE / largest "
             "difference; the 8-bit floor there is the reference rounded, VolPack's bytes are truncated). The scenes "
             "are not VTK's: VolPack has no perspective projection and no colour transfer function (its colour is "
             "the shade table's, per normal), so the ML 256^3 rows are the same volume, tent opacity and angles "
             "seen orthographically in white.")
    L.append("")
    L.append("| case | reference render (1/8 voxel, " + f"{T[-1]} thr) | 8-bit floor (truncated) | VolPack | volref fast, step 1 |")
    L.append("|---|---|---|---|---|")
    for r in recs:
        v = r["volpack_vs_ref8"]
        f1 = next((f for f in r["fast"] if f["step"] == 1.0), None)
        fast1 = "-"
        if f1:
            fast1 = f"{f1['rmse_rgb']:.4f} / {f1['max_rgb']:.3f}"
        t8 = r["trunc8_vs_ref8"]
        L.append(f"| {LABELS.get(r['name'], r['name'])} | {sec(r['render_s']['ref8'])} | {t8['rmse_rgb']:.4f} / {t8['max_rgb']:.3f} "
                 f"| {v['rmse_rgb']:.4f} / {v['max_rgb']:.3f} | {fast1} |")
    L.append("| *VTK's composite / shaded scenes (\"volref beside VTK\"), fixed-point* | | *0.0006 / 0.002 (rounded)* | *fixed-point 0.0098 / 0.323, 0.0220 / 0.152* | *0.0018 / 0.029, 0.0043 / 0.058* |")
    L.append("")
    L.append(f"Reference renders ({T[-1]} threads, once): " + "; ".join(
        f"{r['name']} 1/16 {sec(r['render_s']['ref16'])}, adaptive {sec(r['render_s']['adaptive'])} (its error channel's max {r['adaptive_error_max']:.1e})"
        for r in recs) + ".")
    L.append("")
    L.append(("Every volref image (volpack profile, reference) is the same at every thread count." if meta["images_same"]
              else "**Some volref image differs between thread counts** (see the log)."))
    L.append("")
    if meta.get("timing_rerun"):
        L.append(f"The timing rounds were rerun on their own after the accuracy renders (`bench/volpack/volpack_error.py "
                 f"{meta['out_label']} --timing-only`, the same settings), whose run had shared the machine with other jobs "
                 f"(load average {meta['accuracy']['load_start']} at its start).")
        L.append("")
    w = meta.get("wait")
    if w:
        L.append(f"Before each of the {w['runs']} timed runs the script waited until the CPUs had been at least 90 % idle "
                 f"over half a second (at most 20 s per run, {w['budget_s']:.0f} s in all): {w['idle']} of {w['runs']} runs "
                 f"started that way, after {w['waited_s']:.0f} s of waiting in total. Load average when the timing rounds "
                 f"began: {meta.get('load_timing', '?')}.")
        L.append("")
    L.append(f"Command ({meta['date']}; volref at commit {meta['commit']}; {meta['cpu']}; load average at the start / end "
             f"{meta['load_start']} / {meta['load_end']}; {meta['elapsed']:.0f} s):")
    L.append("```sh")
    L.append(meta["command"])
    L.append("```")
    L.append(f"Settings: VOLPACK_ERR_REPS={meta['reps']}, VOLPACK_ERR_FRAMES={meta['frames']}, "
             f"VOLPACK_ERR_THREADS=\"{' '.join(map(str, T))}\", VOLPACK_ERR_TOLERANCE={meta['tolerance']:g}, "
             f"VOLPACK_ERR_FAST_STEPS=\"{' '.join(f'{s:g}' for s in meta['fast_steps'])}\"; images, continuous scenes and "
             f"results.json in `{meta['out_label']}`.")
    L.append("")
    return "\n".join(L)


def replace_section(doc_path, text):
    with open(doc_path) as f:
        lines = f.read().split("\n")
    new = text.rstrip("\n").split("\n")
    if HEADING in lines:
        start = lines.index(HEADING)
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    else:
        after = lines.index(AFTER_HEADING) if AFTER_HEADING in lines else len(lines) - 1
        start = end = next((i for i in range(after + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    lines[start:end] = new + [""]
    with open(doc_path, "w") as f:
        f.write("\n".join(lines))


def main(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out")
    p.add_argument("--doc")
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--frames", type=int, default=5)
    p.add_argument("--threads", default="1 2")
    p.add_argument("--tolerance", type=float, default=1e-4)
    p.add_argument("--fast-steps", default="0.25 0.5 0.75 1 1.5 2 3 4 6 8 12 16")
    p.add_argument("--scenes", default=" ".join(SCENES))
    p.add_argument("--command", default="bench/volpack_error.sh")
    p.add_argument("--out-label")
    p.add_argument("--report-only", action="store_true", help="rewrite the section from OUT/results.json")
    p.add_argument("--timing-only", action="store_true",
                   help="repeat the timing rounds on OUT's accuracy results (OUT/results.json) and rewrite them")
    a = p.parse_args(argv)
    if a.report_only:
        with open(os.path.join(a.out, "results.json")) as f:
            saved = json.load(f)
        text = section(saved["scenes"], saved["meta"])
        with open(os.path.join(a.out, "section.md"), "w") as f:
            f.write(text)
        if a.doc:
            replace_section(a.doc, text)
        print(text)
        return 0
    start = time.time()
    load_start = " ".join(open("/proc/loadavg").read().split()[:3])
    build = os.environ.get("VOLREF_BUILD", os.path.join(ROOT, "build"))
    tools = Tools(build)
    threads = [int(t) for t in a.threads.split()]
    fast_steps = [float(s) for s in a.fast_steps.split()]
    os.makedirs(a.out, exist_ok=True)
    if not os.path.exists(ML256):
        log(f"writing {ML256}")
        run([sys.executable, os.path.join(ROOT, "bench", "volpack", "make_ml_u8.py"), "256", ML256], "make_ml_u8.py")
    recs = []
    accuracy_meta = None
    if a.timing_only:
        with open(os.path.join(a.out, "results.json")) as f:
            saved = json.load(f)
        recs, accuracy_meta = saved["scenes"], saved["meta"].get("accuracy", saved["meta"])
        for rec in recs:
            work = os.path.join(a.out, rec["name"])
            rec["args"], _ = rc.volpack_args(os.path.join(ROOT, "bench", "volpack", rec["name"] + ".json"), work, rec["name"])
        a.tolerance, fast_steps = accuracy_meta["tolerance"], accuracy_meta["fast_steps"]
    else:
        for name in a.scenes.split():
            log(f"{name}: accuracy renders")
            rec, _ = prepare_scene(tools, name, os.path.join(a.out, name), a.tolerance, fast_steps, max(threads))
            recs.append(rec)
    load_timing = " ".join(open("/proc/loadavg").read().split()[:3])
    images_same = time_rounds(tools, recs, a.reps, a.frames, threads, a.out)
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True).stdout.strip()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    meta = {"threads": threads, "tolerance": a.tolerance, "frames": a.frames, "reps": a.reps, "fast_steps": fast_steps,
            "images_same": images_same, "date": time.strftime("%Y-%m-%d"),
            "commit": commit + (" plus the working tree" if dirty else ""), "cpu": f"{os.cpu_count()} cores, {cpu}",
            "load_start": load_start, "load_end": " ".join(open("/proc/loadavg").read().split()[:3]),
            "elapsed": time.time() - start, "command": a.command, "load_timing": load_timing, "wait": dict(WAIT),
            "out_label": a.out_label or os.path.relpath(a.out, ROOT)}
    meta["accuracy"] = accuracy_meta or {k: meta[k] for k in ("date", "commit", "load_start", "elapsed", "tolerance", "fast_steps")}
    meta["timing_rerun"] = a.timing_only
    if a.timing_only:
        meta["load_start"] = f"{meta['accuracy']['load_start']} (accuracy renders, {meta['accuracy']['date']}); {load_timing}"
        meta["elapsed"] = meta["accuracy"]["elapsed"] + meta["elapsed"]
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump({"meta": meta, "scenes": [{k: v for k, v in r.items() if k != "args"} for r in recs]}, f, indent=1)
    text = section(recs, meta)
    with open(os.path.join(a.out, "section.md"), "w") as f:
        f.write(text)
    if a.doc:
        replace_section(a.doc, text)
        log(f"wrote the section into {a.doc}")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
