#!/usr/bin/python3
"""The VolPack check's synthetic volume (issue 55): tests/volpack/data/marschner-lobb-64.nrrd.

Marschner and Lobb's test signal (1994), alpha = 0.25, f_M = 6, on [-1, 1]^3:
    rho(x, y, z) = (1 - sin(pi z / 2) + alpha (1 + rho_r(sqrt(x^2 + y^2)))) / (2 (1 + alpha)),
    rho_r(r) = cos(2 pi f_M cos(pi r / 2)),
sampled on a 64^3 grid whose first and last samples lie on -1 and 1 (x_i = -1 + 2 i / 63), quantised to
u8 as round(255 rho) (numpy's rint; rho is in [0, 1]). Written as an attached-header NRRD, gzip encoding
(level 9, no time stamp), x fastest.

    make_volumes.py           writes the file
    make_volumes.py --check   verifies that the committed file's samples are this volume (exit 1 if not)
"""
import gzip
import os
import sys

import numpy as np

N = 64
ALPHA = 0.25
FM = 6.0
HERE = os.path.dirname(os.path.abspath(__file__))
PATH = os.path.join(HERE, "data", "marschner-lobb-64.nrrd")
HEADER = (b"NRRD0004\n# Marschner-Lobb, alpha 0.25, f_M 6, on [-1, 1]^3, 64^3 samples, u8 = round(255 rho);"
          b" tests/volpack/make_volumes.py\ntype: uchar\ndimension: 3\nsizes: 64 64 64\nencoding: gzip\n\n")


def samples():
    t = -1.0 + 2.0 * np.arange(N) / (N - 1)
    z, y, x = np.meshgrid(t, t, t, indexing="ij")  # array index [k][j][i]: x fastest in memory
    r = np.sqrt(x * x + y * y)
    rho_r = np.cos(2.0 * np.pi * FM * np.cos(np.pi * r / 2.0))
    rho = (1.0 - np.sin(np.pi * z / 2.0) + ALPHA * (1.0 + rho_r)) / (2.0 * (1.0 + ALPHA))
    return np.rint(255.0 * rho).astype(np.uint8).tobytes()


def main(argv):
    data = samples()
    if argv == ["--check"]:
        with open(PATH, "rb") as f:
            content = f.read()
        ok = content.startswith(HEADER) and gzip.decompress(content[len(HEADER):]) == data
        print(f"make_volumes: {PATH}: {'the Marschner-Lobb volume' if ok else 'NOT the Marschner-Lobb volume of this script'}")
        return 0 if ok else 1
    if argv:
        print(__doc__, file=sys.stderr)
        return 2
    os.makedirs(os.path.dirname(PATH), exist_ok=True)
    with open(PATH, "wb") as f:
        f.write(HEADER + gzip.compress(data, 9, mtime=0))
    print(f"make_volumes: wrote {PATH}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
