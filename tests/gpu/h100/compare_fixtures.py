#!/usr/bin/python3
"""The profiles against the real programs' images recorded on an NVIDIA H100 (tests/gpu/h100/README.md),
without a GPU: each fixture's scene rendered by volref with the profile that mirrors its program, once
with exact texture filtering and once with the H100 texture unit (render.profile_options.texture_unit
"h100", docs/conventions.md section 9, "The texture unit"), each compared with the GPU's image.

    seed002/NAME.json + NAME.h100.exr   seed 002's GLSL program (glsl-basic, float32 texels)
    seed001/NAME.json + NAME.h100.exr   seed 001's CUDA program (cuda-curvilinear, unorm16 texels); pixels
                                        the program marked (-1, outAbs, inAbs, -1) (a loop that never ends,
                                        its guard) are left out and counted

Prints one line per fixture (max |difference| over RGBA and the pixels over `tol` with exact and with h100)
and, with --markdown, the table of docs/gpu-checking.md. With --check (ctest `h100_fixtures`): exit 1
unless glsl-basic with "h100" is at least as close to every seed 002 image as with "exact" (the max
difference and the count over the derived tolerance, derive_tolerance.py). The seed 001 lines are
reported, not checked (issue 28: its geometry is not mirrored in float32 yet).

With --bands (and --check) each fixture is also rendered with texture_unit "h100" and texture_band: every
pixel must lie within the error channel plus 2e-4 (seed 002: plus derive_tolerance.py's bound), and seed
001's `fault` pixels must be exactly the rays the program's guard marked (issue 28).

Usage: compare_fixtures.py VOLREF OUTDIR [--check] [--bands] [--markdown] [--only seed001|seed002] [--fixtures DIR]
"""
import json
import os
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
FIXTURES = HERE  # --fixtures DIR: another folder of seed001/ and seed002/ (tests/gpu/device/collect.sh)


def read_channels(path):
    img = oiio.ImageInput.open(path)
    if img is None:
        sys.exit(f"compare_fixtures.py: cannot read {path}")
    spec = img.spec()
    px = np.asarray(img.read_image(oiio.FLOAT), dtype=np.float64).reshape(spec.height, spec.width, spec.nchannels)
    names = list(spec.channelnames)
    img.close()
    return {n: px[:, :, names.index(n)] for n in names}


def read_rgba(path):
    ch = read_channels(path)
    return np.stack([ch[c] for c in "RGBA"], axis=2)


def render(volref, scene, out, sets):
    cmd = [volref, "render", scene, "-o", out] + sum((["--set", s] for s in sets), [])
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"compare_fixtures.py: {' '.join(cmd)} failed: {r.stderr.strip()}")


def tolerance(scene):
    """glsl: derive_tolerance.py's bound where it applies (gaussian fields), else 2e-3 (seed 001's compare.sh)."""
    tool = os.path.join(HERE, "..", "glsl", "derive_tolerance.py")
    r = subprocess.run(["/usr/bin/python3", tool, scene], capture_output=True, text=True)
    return float(r.stdout.strip()) if r.returncode == 0 else 2e-3


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    only = None
    if "--only" in argv:
        only = argv[argv.index("--only") + 1]
        args.remove(only)
    global FIXTURES
    if "--fixtures" in argv:
        FIXTURES = argv[argv.index("--fixtures") + 1]
        args.remove(FIXTURES)
    volref, outdir = args[0], args[1]
    os.makedirs(outdir, exist_ok=True)
    rows, failures = [], []
    for seed, profile, extra in (("seed002", "glsl-basic", []),
                                 ("seed001", "cuda-curvilinear", ["render.profile_options.texture_format=unorm16"])):
        if only and seed != only:
            continue
        if seed == "seed001" and "--check" in argv and "--markdown" not in argv:
            continue  # the check needs seed 002's exact-against-h100 lines only (seed 001: the bands below)
        folder = os.path.join(FIXTURES, seed)
        for name in sorted(f[:-5] for f in os.listdir(folder) if f.endswith(".json")):
            scene = os.path.join(folder, name + ".json")
            gpu = read_rgba(os.path.join(folder, name + ".h100.exr"))
            hung = (gpu[:, :, 0] == -1) & (gpu[:, :, 3] == -1)
            tol = tolerance(scene) if seed == "seed002" else 2e-3
            res = {}
            for unit in ("exact", "h100"):
                out = os.path.join(outdir, f"{seed}-{name}-{unit}.exr")
                render(volref, scene, out, [f"render.profile={profile}", f"render.profile_options.texture_unit={unit}"] + extra)
                d = np.abs(read_rgba(out) - gpu)
                d[hung] = 0.0
                res[unit] = (d.max(), int((d.max(axis=2) > tol).sum()), float(np.sqrt((d ** 2).mean())))
            rows.append((seed, name, tol, res, int(hung.sum())))
            e, h = res["exact"], res["h100"]
            print(f"{seed}/{name:20s} tol {tol:.3g}  exact: max {e[0]:.3g} over {e[1]:5d} rms {e[2]:.3g}   "
                  f"h100: max {h[0]:.3g} over {h[1]:5d} rms {h[2]:.3g}   unfinished {int(hung.sum())}")
            if seed == "seed002" and (h[0] > e[0] or h[1] > e[1]):
                failures.append(f"{seed}/{name}: h100 further than exact (max {h[0]:.3g} > {e[0]:.3g} or over {h[1]} > {e[1]})")
    # issue 28: each profile as its program runs on the H100, with the error channel (texture_band: the
    # texture unit's family, and for seed 001's float32 kernel what float32, FMA and CUDA's math functions
    # may change): every pixel within the channel plus 2e-4 (seed 002: plus derive_tolerance.py's bound),
    # and seed 001's fault pixels exactly the rays the program's guard marked.
    if "--check" in argv or "--bands" in argv:
        print("\nwith texture_unit h100 and texture_band (the error channel):")
        for seed, profile, extra in (("seed002", "glsl-basic", []), ("seed001", "cuda-curvilinear", [])):
            if only and seed != only:
                continue
            folder = os.path.join(FIXTURES, seed)
            for name in sorted(f[:-5] for f in os.listdir(folder) if f.endswith(".json")):
                scene = os.path.join(folder, name + ".json")
                gpu = read_rgba(os.path.join(folder, name + ".h100.exr"))
                hung = (gpu[:, :, 0] == -1) & (gpu[:, :, 3] == -1)
                out = os.path.join(outdir, f"{seed}-{name}-band.exr")
                render(volref, scene, out, [f"render.profile={profile}", "render.profile_options.texture_unit=h100",
                                            "render.profile_options.texture_band=true"] + extra)
                ch = read_channels(out)
                mine = np.stack([ch[c] for c in "RGBA"], axis=2)
                err = ch["error"]
                fault = ch["fault"] > 0 if "fault" in ch else np.zeros_like(err, dtype=bool)
                base = tolerance(scene) if seed == "seed002" else 2e-4
                d = np.abs(mine - gpu).max(axis=2)
                ok = fault | hung
                over = (~ok) & ~(d <= err + base)
                fin = err[np.isfinite(err) & ~ok]
                fault_mismatch = int((fault != hung).sum())
                print(f"{seed}/{name:20s} base {base:.3g}  over {int(over.sum()):4d}  max|d| {d[~ok].max() if (~ok).any() else 0:.3g}  "
                      f"error: median {np.median(fin) if fin.size else 0:.3g} max finite {fin.max() if fin.size else 0:.3g} "
                      f"infinite {int((~np.isfinite(err) & ~ok).sum())}  fault {int(fault.sum())} gpu {int(hung.sum())} mismatch {fault_mismatch}")
                if over.any() or fault_mismatch:
                    ys, xs = np.nonzero(over)
                    failures.append(f"{seed}/{name}: {int(over.sum())} pixels outside the error channel + {base:.3g} "
                                    f"(first {list(zip(xs[:5].tolist(), ys[:5].tolist()))}), fault/GPU-mark mismatch {fault_mismatch}")
    if "--markdown" in argv:
        print("\n| fixture | tolerance | exact: max, pixels over, rms | h100: max, pixels over, rms | unfinished rays |")
        print("|---|---|---|---|---|")
        for seed, name, tol, res, hung in rows:
            e, h = res["exact"], res["h100"]
            print(f"| {seed}/{name} | {tol:.3g} | {e[0]:.3g}, {e[1]}, {e[2]:.2g} | {h[0]:.3g}, {h[1]}, {h[2]:.2g} | {hung} |")
    if "--check" in argv and failures:
        print("\n".join(failures), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
