#!/usr/bin/python3
"""The 8-bit Marschner-Lobb volume of the VolPack benchmark (issue 55; bench/volpack/README.md).

    make_ml_u8.py N OUT.nrrd      writes N^3 samples, u8, raw encoding (attached header), x fastest
    make_ml_u8.py --check         N = 64 must give tests/volpack/data/marschner-lobb-64.nrrd's samples

The field is volref's procedural "marschner-lobb" (fm 6, alpha 0.25: core/grid/ProceduralField.cpp, the
field bench/make_ml_volume writes as floats for the VTK benchmarks) at x_i = -1 + 2 i / (N - 1),
quantised as tests/volpack/make_volumes.py does: round(255 rho) (numpy's rint; rho is in [0, 1]).
VolPack needs 8-bit voxels. bench/volpack/volpack_error.py writes build/volpack-bench/marschner-lobb-256.nrrd
with it (gitignored; about 16 MiB).
"""
import gzip
import os
import sys

import numpy as np

ALPHA = 0.25
FM = 6.0
ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def samples(n):
    t = -1.0 + 2.0 * np.arange(n) / (n - 1)
    z, y, x = np.meshgrid(t, t, t, indexing="ij")  # [k][j][i]: x fastest in memory
    r = np.sqrt(x * x + y * y)
    rho_r = np.cos(2.0 * np.pi * FM * np.cos(np.pi * r / 2.0))
    rho = (1.0 - np.sin(np.pi * z / 2.0) + ALPHA * (1.0 + rho_r)) / (2.0 * (1.0 + ALPHA))
    return np.rint(255.0 * rho).astype(np.uint8).tobytes()


def write(n, path):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    header = (f"NRRD0004\n# Marschner-Lobb, alpha {ALPHA}, f_M {FM:g}, on [-1, 1]^3, {n}^3 samples, u8 = round(255 rho);"
              f" bench/volpack/make_ml_u8.py\ntype: uchar\ndimension: 3\nsizes: {n} {n} {n}\nencoding: raw\n\n")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(header.encode() + samples(n))
    os.replace(tmp, path)


def check():
    path = os.path.join(ROOT, "tests", "volpack", "data", "marschner-lobb-64.nrrd")
    with open(path, "rb") as f:
        content = f.read()
    body = gzip.decompress(content[content.index(b"\n\n") + 2:])
    ok = body == samples(64)
    print(f"make_ml_u8: N = 64 {'gives' if ok else 'does NOT give'} the samples of {path}")
    return 0 if ok else 1


def main(argv):
    if argv == ["--check"]:
        return check()
    if len(argv) != 2 or not argv[0].isdigit() or int(argv[0]) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    write(int(argv[0]), argv[1])
    print(f"make_ml_u8: wrote {argv[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
