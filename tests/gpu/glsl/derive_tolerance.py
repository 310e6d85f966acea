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
    G      = max |grad f|                 (gaussian fields: amplitude / sigma e^-1/2; other procedural
                                          fields: the voxels' differences, max_gradient)
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


def max_gradient(src, dims, spacing, origin):
    """max |grad f| of what the shader samples: for a Gaussian the field's own bound amplitude / sigma e^-1/2;
    for any other field (issue 28) that of the trilinear interpolant of its voxels, whose partial derivative
    along an axis is a convex combination of the voxel differences along it: |df/dx_a| <= max |dv_a| / s_a,
    so |grad f| <= sqrt(sum_a (max |dv_a| / s_a)^2) (exact for every data set)."""
    kind = src["field"]
    if kind == "gaussian":
        return src.get("amplitude", 1.0) / src["sigma"] * math.exp(-0.5)
    import numpy as np  # Debian's python3-numpy
    nx, ny, nz = dims
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    x, y, z = (origin[0] + i * spacing[0], origin[1] + j * spacing[1], origin[2] + k * spacing[2])
    if kind == "constant":
        f = np.full(i.shape, float(src.get("value", 0.0)))
    elif kind == "linear":
        a = src.get("coefficients", [0, 0, 0, 0])
        f = a[0] * x + a[1] * y + a[2] * z + a[3]
    elif kind == "radial":
        c = src.get("center", [0, 0, 0])
        f = np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2)
    elif kind == "marschner-lobb":
        fm, alpha = src.get("fm", 6.0), src.get("alpha", 0.25)
        mx, my, mz = (-1.0 + 2.0 * q / max(n - 1, 1) for q, n in ((i, nx), (j, ny), (k, nz)))
        r = np.sqrt(mx * mx + my * my)
        rho = np.cos(2 * math.pi * fm * np.cos(math.pi * r / 2))
        f = (1 - np.sin(math.pi * mz / 2) + alpha * (1 + rho)) / (2 * (1 + alpha))
    elif kind == "cells":
        f = np.asarray(src["values"], dtype=np.float64).reshape(nz, ny, nx)
    else:
        sys.exit(f"derive_tolerance.py: no gradient bound for field {kind}")
    g = 0.0
    for axis, s_a in ((2, spacing[0]), (1, spacing[1]), (0, spacing[2])):
        d = np.abs(np.diff(f, axis=axis))
        g += (d.max() / s_a) ** 2 if d.size else 0.0
    return math.sqrt(g)


def main(path):
    s = json.load(open(path))
    v = s["volume"]
    src = v["source"]
    if "field" not in src:
        sys.exit("derive_tolerance.py: procedural fields only (volume.source.field)")
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
    G = max_gradient(src, dims, spacing, origin)
    K = r.get("profile_options", {}).get("intensity", 1.0)
    rows = v["transfer"]["opacity"]
    S = max([abs((b[1] - a[1]) / (b[0] - a[0])) for a, b in zip(rows, rows[1:]) if b[0] > a[0]] + [0.0]) * K
    dx = E * u * (N + 8 * c)
    dv = G * dx + 4 * u
    tol = dv * (1 + S * N) + 8 * u * N * (1 + K)
    print(f"{tol:.3e}")


if __name__ == "__main__":
    main(sys.argv[1])
