#!/usr/bin/python3
"""Image error against volref's reference, and the image reader the comparison uses.

    /usr/bin/python3 bench/vtk/compare.py REFERENCE.exr IMAGE.png [IMAGE.png ...]

Images are read through OpenImageIO's `oiiotool --dumpdata` (every pixel as text), because this is
the one reader here that was found to decode all the files involved correctly: Debian 12's VTK 9.1
vtkTIFFReader misreads volref's 16-bit RGBA TIFFs, and OIIO 2.4.7 writes wrong values into 16-bit
PPMs. EXR values are read as the floats they are (printed to 9 decimals); 8-bit PNGs as q / 255.

Every image is compared as RGB in [0, 1] composited over opaque black: the reference EXR holds
premultiplied RGBA, so over black its RGB is the colour itself; volref's PNGs are written over the
scenes' opaque black background and VTK's are rendered over a black background. Prints, per image,
the RMSE over all pixels and the 3 channels (background pixels included) and the largest absolute
difference.
"""
import json
import re
import subprocess
import sys

import numpy as np

_HEADER = re.compile(r":\s+(\d+) x\s+(\d+), (\d+) channel, (\w+)")


def read_image(path):
    """Returns an (H, W, channels) float64 array of the image in [0, 1] (rows top to bottom)."""
    text = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    lines = text.splitlines()
    m = _HEADER.search(lines[0])
    if not m:
        raise SystemExit(f"compare.py: cannot parse oiiotool's header for {path}: {lines[0]!r}")
    w, h, nch, fmt = int(m.group(1)), int(m.group(2)), int(m.group(3)), m.group(4)
    scale = {"uint8": 255.0, "uint16": 65535.0, "float": 1.0, "half": 1.0}.get(fmt)
    if scale is None:
        raise SystemExit(f"compare.py: {path}: unsupported pixel type {fmt}")
    body = [ln.split(":", 1)[1] for ln in lines[1:] if ln.lstrip().startswith("Pixel (")]
    if len(body) != w * h:
        raise SystemExit(f"compare.py: {path}: expected {w * h} pixels, read {len(body)}")
    # "r g b a (r' g' b' a')" for integer types: keep the raw values before the bracket.
    values = np.array(" ".join(b.split("(", 1)[0] for b in body).split(), dtype=np.float64)
    return values.reshape(h, w, nch) / scale


def read_rgb(path):
    """Returns an (H, W, 3) float64 array of the image's RGB in [0, 1] (rows top to bottom)."""
    return read_image(path)[..., :3]


def errors(reference, image):
    d = image - reference
    return {"rmse": float(np.sqrt(np.mean(d * d))), "max": float(np.max(np.abs(d)))}


def quantised(reference, bits=8):
    """The reference as a perfect renderer would write it to an 8-bit file (round half away from 0)."""
    q = 2 ** bits - 1
    return np.floor(np.clip(reference, 0.0, 1.0) * q + 0.5) / q


if __name__ == "__main__":
    if len(sys.argv) < 3:
        raise SystemExit("usage: compare.py REFERENCE.exr IMAGE [IMAGE ...]")
    ref = read_rgb(sys.argv[1])
    out = {"8-bit floor": errors(ref, quantised(ref))}
    for p in sys.argv[2:]:
        out[p] = errors(ref, read_rgb(p))
    print(json.dumps(out, indent=1))
