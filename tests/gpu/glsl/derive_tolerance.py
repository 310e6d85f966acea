#!/usr/bin/python3
"""The tolerance of one glsl test (docs/gpu-checking.md, "glsl-basic against seed 002's program"): a
first-order bound on how far seed 002's shader in float32 (glsl_raycaster on llvmpipe) can be from the
glsl-basic profile in double on the same scene, from the arithmetic alone.

    u      = 2^-24                        float32 unit roundoff
    N      = floor(diag / h) + 1          the most samples a ray takes (diag: the domain's diagonal)
    E      = the largest extent            (world units; the cube's [0, 1] per axis)
    c      = the largest |ray origin| in cube coordinates (the eye; orthographic: the image plane's corners)
    dx     = E u (N + 8 c)                position error of the last sample: the entry point from an origin
                                          of size c (8 roundings), then N additions pos += dir * step
    G      = max |grad f|                 (gaussian fields: amplitude / sigma e^-1/2)
    dv     = G dx + 4 u                   value error: position error, plus the filter's float weights
    S      = K max |slope| of the opacity rows (K the intensity)
    tol    = dv (1 + S N) + 8 u N (1 + K)

Compositing C = sum_k T_k a_k v_k: a sample's value error moves C by at most T_k a_k dv (sum T_k a_k <= 1)
and its opacity error S dv moves C and A by at most T_k S dv (sum T_k <= N); each of the N steps rounds
its products and sums (8 u, times K for the opacity). Discontinuities are outside the bound (the 0.01
cutoff and the exit test decide a sample in or out): the scenes keep them transparent or away from
rounding ties. Shading adds a normal error 2 |dg| / |grad f| that has no finite bound where grad f -> 0
(the field's maximum); shaded scenes use the unshaded bound and docs/gpu-checking.md gives the measured
margin.

Usage: derive_tolerance.py SCENE.json   (prints the tolerance)
"""
import json
import math
import sys


def main(path):
    s = json.load(open(path))
    v = s["volume"]
    src = v["source"]
    if src.get("field") != "gaussian":
        sys.exit("derive_tolerance.py: gaussian fields only (max |grad f| in closed form)")
    dims = src["dims"]
    spacing = v.get("spacing", [1, 1, 1])
    origin = v.get("origin", [0, 0, 0])
    ext = [(n - 1) * d for n, d in zip(dims, spacing)]
    E = max(ext)
    r = s["render"]
    if r.get("step_units") != "world":
        sys.exit("derive_tolerance.py: render.step_units world only")
    h = r["step"]
    N = math.floor(math.sqrt(sum(e * e for e in ext)) / h) + 1
    u = 2.0 ** -24
    cam = s["camera"]
    eye = [(cam["eye"][a] - origin[a]) / ext[a] for a in range(3)]
    c = math.sqrt(sum(x * x for x in eye))
    if cam["type"] == "orthographic":
        w, hgt = s["image"]["width"], s["image"]["height"]
        c += 0.5 * cam["height"] * math.hypot(1.0, w / hgt) / min(ext)
    G = src.get("amplitude", 1.0) / src["sigma"] * math.exp(-0.5)
    K = r.get("profile_options", {}).get("intensity", 1.0)
    rows = v["transfer"]["opacity"]
    S = max([abs((b[1] - a[1]) / (b[0] - a[0])) for a, b in zip(rows, rows[1:]) if b[0] > a[0]] + [0.0]) * K
    dx = E * u * (N + 8 * c)
    dv = G * dx + 4 * u
    tol = dv * (1 + S * N) + 8 * u * N * (1 + K)
    print(f"{tol:.3e}")


if __name__ == "__main__":
    main(sys.argv[1])
