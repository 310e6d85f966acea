#!/usr/bin/python3
"""Speed at equal error (issue 19): volref's settings against vtkFixedPointVolumeRayCastMapper on the
benchmark frame, measured in one interleaved run, written as docs/performance.md's section
"## Speed at equal error". bench/speed_at_equal_error.sh runs it under xvfb-run (VTK needs an X server).

    xvfb-run -a /usr/bin/python3 bench/vtk/equal_error.py OUT [--doc docs/performance.md]

The frame: bench/vtk/scenes/composite.json (Marschner-Lobb 256^3 over [-127.5, 127.5]^3, 512 x 512,
perspective, composite unshaded, the tent opacity around f = 0.5), its volume read by volref as the
float32 NRRD file bench/make_ml_volume writes (VTK builds the same float32 field with numpy).

Steps:
 1. freeze the volref binary (OUT/bin; LD_LIBRARY_PATH beats the RUNPATH);
 2. the fine reference: volref, reference profile, step REF_STEP voxel (default 1/8), EXR;
 3. R rounds (--reps), each: for each thread count, VTK fixed-point (1 warm-up + F timed frames), then
    every volref setting (profile x step) with `--timing --repeat F` (frame times only: no file
    reading, volume generation or set-up, as VTK's frames);
 4. every image's error against the fine reference: RGB over black, max |difference| and RMSE over all
    pixels and channels (VTK's PNG is 8-bit, volref's EXR float);
 5. the tables: frame time (median over rounds x frames), samples per second per core, error, the
    equal-error ratio (VTK's frame time over the fastest volref setting whose max error and RMSE are
    both at most VTK's), the reference at step 1 against VTK, 1 -> 2 threads, time against step.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import compare  # noqa: E402  (read_rgb, errors)

SECTION = "## Speed at equal error"

ap = argparse.ArgumentParser()
ap.add_argument("out")
ap.add_argument("--doc", help="docs/performance.md: its section SECTION is replaced (or inserted)")
ap.add_argument("--build", default=os.environ.get("VOLREF_BUILD", os.path.join(ROOT, "build")))
ap.add_argument("--reps", type=int, default=3, help="interleaved rounds")
ap.add_argument("--frames", type=int, default=3, help="timed frames per run (volref --repeat, VTK --frames)")
ap.add_argument("--threads", default="1 2")
ap.add_argument("--ref-step", type=float, default=0.125)
ap.add_argument("--reference-steps", default="0.5 1 2 3 4")
ap.add_argument("--fast-steps", default="1 2 2.25 2.3 2.4 2.5 3 4 6")
# issue 31: the fast profile with pre-integrated segments (render.profile_options.preintegration = the table's
# intervals per axis), named "pre<table>-<step>"
ap.add_argument("--pre-steps", default="2 3 4 6")
ap.add_argument("--pre-table", type=int, default=256)
ap.add_argument("--command", default="bench/speed_at_equal_error.sh")
a = ap.parse_args()

out = os.path.abspath(a.out)
for sub in ("bin", "images", "runs"):
    shutil.rmtree(os.path.join(out, sub), ignore_errors=True)
    os.makedirs(os.path.join(out, sub))
scene = os.path.join(HERE, "scenes", "composite.json")
threads = [int(t) for t in a.threads.split()]
PRE = "pre%d" % a.pre_table
settings = [("reference", float(s)) for s in a.reference_steps.split()] + [("fast", float(s)) for s in a.fast_steps.split()] + \
    [(PRE, float(s)) for s in a.pre_steps.split()]


def profile_args(profile):
    if profile == PRE:
        return ["--set", "render.profile=fast", "--set", "render.profile_options.preintegration=%d" % a.pre_table]
    return ["--set", "render.profile=" + profile]
start = time.time()


def log(msg):
    print(time.strftime("%H:%M:%S") + " [equal-error] " + msg, file=sys.stderr, flush=True)


def step_text(s):
    return ("%g" % s)


# 1. The frozen binary and the float32 volume.
shutil.copy(os.path.join(a.build, "cli", "volref"), os.path.join(out, "bin", "volref"))
for lib in ("libvolref_core.so.0", "libvolref_tools.so.0", "libvolref_image_files.so"):
    shutil.copy(os.path.realpath(os.path.join(a.build, lib)), os.path.join(out, "bin", lib))
env = dict(os.environ, LD_LIBRARY_PATH=os.path.join(out, "bin") + ":" + os.environ.get("LD_LIBRARY_PATH", ""))
volume = os.path.join(out, "ml256.nrrd")
if not os.path.exists(volume):
    subprocess.run([os.path.join(a.build, "bench", "make_ml_volume"), "256", volume, "f32"], check=True)
source = ["--set", "volume.source=" + volume]


def volref(args):
    r = subprocess.run([os.path.join(out, "bin", "volref")] + args, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("volref failed: volref %s\n%s" % (" ".join(args), r.stderr))
    timing = [ln for ln in r.stderr.splitlines() if ln.startswith("volref: timing ")]
    return json.loads(timing[-1][len("volref: timing "):]) if timing else None


def vtk(t, png):
    r = subprocess.run(["/usr/bin/python3", os.path.join(HERE, "vtk_render.py"), scene, "--mapper", "fixed",
                        "--threads", str(t), "--frames", str(a.frames), "--warmup", "1", "-o", png],
                       env=dict(os.environ, LP_NUM_THREADS=str(t)), capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("VTK fixed-point failed:\n" + r.stderr)
    return json.loads(r.stdout.strip().splitlines()[-1])


# 2. The fine reference.
ref_exr = os.path.join(out, "reference.exr")
log("fine reference: step %g voxel" % a.ref_step)
volref(["render", scene, "-o", ref_exr, "--threads", str(os.cpu_count() or 1), "--set", "render.step=%g" % a.ref_step] + source)

# 3. The interleaved rounds.
frames = {}   # (name, threads) -> list of frame times
samples = {}  # name -> samples per frame (positions, as volref counts them)
loads = [open("/proc/loadavg").read().split()[:3]]
for rep in range(1, a.reps + 1):
    for t in threads:
        log("round %d/%d, %d thread(s): VTK fixed-point, then %d volref settings" % (rep, a.reps, t, len(settings)))
        r = vtk(t, os.path.join(out, "images", "vtk-fixed-t%d.png" % t))
        frames.setdefault(("vtk", t), []).extend(r["frames_s"])
        for profile, step in settings:
            name = "%s-%s" % (profile, step_text(step))
            r = volref(["render", scene, "-o", os.path.join(out, "images", "%s-t%d.exr" % (name, t)), "--threads", str(t),
                        "--timing", "--repeat", str(a.frames)] + profile_args(profile) +
                       ["--set", "render.step=%g" % step] + source)
            frames.setdefault((name, t), []).extend(r["frames_s"])
            samples[name] = r["samples"]
            with open(os.path.join(out, "runs", "%s-t%d-%d.json" % (name, t, rep)), "w") as f:
                json.dump(r, f)
loads.append(open("/proc/loadavg").read().split()[:3])

# 4. Errors (the last round's images at the largest thread count; every thread count's image is checked
#    to be the same as the largest's).
log("errors against the fine reference")
ref = compare.read_rgb(ref_exr)
err = {}
tmax = max(threads)
err["vtk"] = compare.errors(ref, compare.read_rgb(os.path.join(out, "images", "vtk-fixed-t%d.png" % tmax)))
same_across_threads = True
for profile, step in settings:
    name = "%s-%s" % (profile, step_text(step))
    img = compare.read_rgb(os.path.join(out, "images", "%s-t%d.exr" % (name, tmax)))
    err[name] = compare.errors(ref, img)
    for t in threads:
        if t != tmax and (compare.read_rgb(os.path.join(out, "images", "%s-t%d.exr" % (name, t))) != img).any():
            same_across_threads = False
floor = compare.errors(ref, compare.quantised(ref))


# 5. The tables.
def med(name, t):
    return statistics.median(frames[(name, t)])


names = ["%s-%s" % (p, step_text(s)) for p, s in settings]
lines = [SECTION, "",
         "*Written by `%s` (bench/vtk/equal_error.py); rerunning the command replaces this section.*" % a.command, "",
         "The benchmark frame: `bench/vtk/scenes/composite.json` (Marschner-Lobb 256^3, fm 6, alpha "
         "0.25, over [-127.5, 127.5]^3; 512 x 512, perspective, composite unshaded, the tent opacity around f = 0.5, "
         "opacity unit distance 4), volref reading the float32 NRRD of `bench/make_ml_volume` (VTK builds the same "
         "float32 field). Frame times only: volref's `--timing --repeat %d` frames (after its set-up), VTK's %d timed "
         "frames after one warm-up frame (vtkFixedPointVolumeRayCastMapper, `SetSampleDistance(1)`, no automatic "
         "adjustment). %d interleaved rounds: in each, for each thread count, VTK and then every volref setting. "
         "Medians over all rounds and frames." % (a.frames, a.frames, a.reps), "",
         "Error: every image against volref's reference profile at step %g voxel (EXR), as RGB over black: the "
         "largest absolute difference and the RMSE over all pixels and channels. VTK's image is an 8-bit PNG, so "
         "its error includes 8-bit rounding (the reference rounded to 8 bits alone: max %.4f, RMSE %.5f); volref's "
         "are float EXR." % (a.ref_step, floor["max"], floor["rmse"]), ""]

head = "| setting | max error | RMSE | " + " | ".join("frame, %d thr" % t for t in threads) + " | " + \
       " | ".join("VTK / this, %d thr" % t for t in threads) + " | samples per frame | " + \
       " | ".join("M samples/s/core, %d thr" % t for t in threads) + " |"
lines += [head, "|" + "---|" * (head.count("|") - 1)]
row = "| VTK fixed-point, step 1 | %.4f | %.5f | " % (err["vtk"]["max"], err["vtk"]["rmse"])
row += " | ".join("%.3f s" % med("vtk", t) for t in threads) + " | " + " | ".join("1" for t in threads) + " | - | "
row += " | ".join("-" for t in threads) + " |"
lines.append(row)
for name in names:
    e = err[name]
    row = "| volref %s, step %s | %.4f | %.5f | " % (name.split("-")[0], name.split("-", 1)[1], e["max"], e["rmse"])
    row += " | ".join("%.3f s" % med(name, t) for t in threads) + " | "
    row += " | ".join("%.2fx" % (med("vtk", t) / med(name, t)) for t in threads) + " | %.2f M | " % (samples[name] / 1e6)
    row += " | ".join("%.1f" % (samples[name] / med(name, t) / t / 1e6) for t in threads) + " |"
    lines.append(row)
lines.append("")

equal = [n for n in names if err[n]["max"] <= err["vtk"]["max"] and err[n]["rmse"] <= err["vtk"]["rmse"]]
summary = []
for t in threads:
    if equal:
        best = min(equal, key=lambda n: med(n, t))
        summary.append("- **Equal error, %d thread(s)**: the fastest setting whose max error and RMSE are both at most "
                       "VTK's is volref %s: %.3f s against VTK's %.3f s, **%.2fx** VTK's frame rate (target 5x)."
                       % (t, best, med(best, t), med("vtk", t), med("vtk", t) / med(best, t)))
    else:
        summary.append("- **Equal error, %d thread(s)**: no setting reaches VTK's error on both measures." % t)
if "reference-1" in names:
    for t in threads:
        summary.append("- **Reference profile at step 1, %d thread(s)**: %.3f s, **%.2fx** VTK's frame rate (target 1.5x)."
                       % (t, med("reference-1", t), med("vtk", t) / med("reference-1", t)))
if len(threads) >= 2:
    t1, t2 = threads[0], threads[1]
    sc = ["%s %.2fx" % (n, med(n, t1) / med(n, t2)) for n in names]
    summary.append("- **Threads %d -> %d** (target at least 1.8x): %s; VTK %.2fx." % (t1, t2, "; ".join(sc), med("vtk", t1) / med("vtk", t2)))
for profile in ("reference", "fast", PRE):
    steps = [s for p, s in settings if p == profile]
    pairs = [(x, y) for x in steps for y in steps if abs(y - 2 * x) < 1e-12]
    if pairs:
        t = threads[0]
        parts = ["step %g -> %g: %.2fx faster" % (x, y, med("%s-%s" % (profile, step_text(x)), t) / med("%s-%s" % (profile, step_text(y)), t))
                 for x, y in pairs]
        summary.append("- **Time against step, %s, %d thread(s)** (target: halving the step at most doubles the frame "
                       "time, doubling it at least 1.6x faster): %s." % (profile, t, "; ".join(parts)))
summary.append("- Every volref image is %s at every thread count." % ("the same" if same_across_threads else "NOT the same"))
lines += summary + [""]
lines += ["Command (%s; volref at commit %s; %d cores, %s; load average at the start / end %s / %s; %.0f s):" % (
    time.strftime("%Y-%m-%d"),
    subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip() or "?",
    os.cpu_count() or 0,
    next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?"),
    " ".join(loads[0]), " ".join(loads[1]), time.time() - start), "```sh", a.command, "```", ""]
section = "\n".join(lines)
with open(os.path.join(out, "section.md"), "w") as f:
    f.write(section)
with open(os.path.join(out, "results.json"), "w") as f:
    json.dump({"frames": {"%s-t%d" % k: v for k, v in frames.items()}, "errors": err, "samples": samples}, f, indent=1)
print(section)

if a.doc:
    text = open(a.doc).read()
    if SECTION in text:
        i = text.index(SECTION)
        j = text.find("\n## ", i + len(SECTION))
        text = text[:i] + section + ("\n" + text[j + 1:] if j >= 0 else "")
    else:
        anchor = "## volref beside VTK"
        i = text.find(anchor)
        text = text[:i] + section + "\n" + text[i:] if i >= 0 else text.rstrip("\n") + "\n\n" + section
    with open(a.doc, "w") as f:
        f.write(text)
    log("wrote the section to " + a.doc)
