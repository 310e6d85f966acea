#!/usr/bin/python3
"""Counts the samples volref takes to render a scene (bench/vtk/scenes/*.json), from the geometry.

    /usr/bin/python3 bench/vtk/count_samples.py bench/vtk/scenes/composite.json

Rebuilds volref's pixel rays (docs/conventions.md section 10: ray through (x + 0.5, y + 0.5);
perspective direction normalize(f + nx tan(fov/2) (W/H) r + ny tan(fov/2) u)) and intersects each
with the volume's domain box by the slab test, in double precision, vectorised with numpy. A ray
with chord L > 0 takes n = max(1, ceil(L / h - 1e-9)) samples (section 4, one per segment, at its
midpoint). Only box bounds equal to the domain and perspective cameras are supported.

Prints one JSON object: rays (pixels), hits (rays with a chord > 0), mean chord (world units) over
the hits, step h, samples (the exact sum of n) and hits x mean chord / h (the brief's estimate).
VTK's mappers take about the same number of samples at the same sample distance (+-1 per ray); the
comparison uses volref's count for all three renderers, so "samples/s" means the same work for
each: VTK's fixed-point mapper skips empty blocks and stops at opacity 1 - 1/255, so it evaluates
fewer samples than this count in the composite cases.
"""
import json
import math
import sys

import numpy as np


def count(scene):
    vs = scene["volume"]
    src = vs["source"]
    dims = np.array(src.get("dims", [2, 2, 2]) if isinstance(src, dict) else None, dtype=np.float64)
    origin = np.array(vs.get("origin", [0, 0, 0]), dtype=np.float64)
    spacing = np.array(vs.get("spacing", [1, 1, 1]), dtype=np.float64)
    if "bounds" in vs and (vs["bounds"].get("min") or vs["bounds"].get("max")):
        raise SystemExit("count_samples.py: only the default bounds (the domain) are supported")
    lo, hi = origin, origin + (dims - 1) * spacing

    cam = scene["camera"]
    if cam.get("type") != "perspective":
        raise SystemExit("count_samples.py: only perspective cameras are supported")
    eye = np.array(cam.get("eye", [0, 0, 1]), dtype=np.float64)
    target = np.array(cam.get("target", [0, 0, 0]), dtype=np.float64)
    up = np.array(cam.get("up", [0, 1, 0]), dtype=np.float64)
    f = (target - eye) / np.linalg.norm(target - eye)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    img = scene.get("image", {})
    W, H = img.get("width", 256), img.get("height", 256)
    t = math.tan(math.radians(cam.get("fov_y", 30)) / 2.0)
    x, y = np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64))
    nx = 2.0 * (x + 0.5) / W - 1.0
    ny = 1.0 - 2.0 * (y + 0.5) / H
    d = f + (nx * t * (W / H))[..., None] * r + (ny * t)[..., None] * u
    d /= np.linalg.norm(d, axis=-1, keepdims=True)

    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t0 = (lo - eye) * inv
        t1 = (hi - eye) * inv
    # Directions exactly 0 on an axis: the slab holds for all t or none.
    zero = d == 0.0
    inside = (eye >= lo) & (eye <= hi)
    t0 = np.where(zero, np.where(inside, -np.inf, np.inf), t0)
    t1 = np.where(zero, np.where(inside, np.inf, -np.inf), t1)
    tnear = np.maximum(np.max(np.minimum(t0, t1), axis=-1), 0.0)
    tfar = np.min(np.maximum(t0, t1), axis=-1)
    chord = np.where(tfar > tnear, tfar - tnear, 0.0)
    hit = chord > 0.0

    render = scene.get("render", {})
    step = render.get("step", 0.5)
    if render.get("step_units", "voxel") == "voxel":
        step *= float(spacing.min())
    n = np.where(hit, np.maximum(1.0, np.ceil(chord / step - 1e-9)), 0.0)
    hits = int(hit.sum())
    mean_chord = float(chord[hit].mean()) if hits else 0.0
    return {"rays": W * H, "hits": hits, "mean_chord": mean_chord, "step": step,
            "samples": int(n.sum()), "estimate": hits * mean_chord / step}


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit("usage: count_samples.py SCENE.json")
    with open(sys.argv[1]) as fh:
        print(json.dumps(count(json.load(fh))))
