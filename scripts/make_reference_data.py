#!/usr/bin/env python3
"""Makes reference_scenes/data/gaussian.nrrd: a 32^3 u16 Gaussian blob, gzip-encoded, little-endian,
with spacings (1, 1, 2) and a space origin, so the NRRD path of the renderer has a real file to read.
Pure Python (no numpy): value(i, j, k) = round(60000 exp(-|p - c|^2 / (2 * 6^2))) with p = (i, j, 2 k),
c = (15.5, 15.5, 31). Regenerate with: /usr/bin/python3 scripts/make_reference_data.py"""
import gzip, math, os, struct

n = 32
values = []
for k in range(n):
    for j in range(n):
        for i in range(n):
            d2 = (i - 15.5) ** 2 + (j - 15.5) ** 2 + (2 * k - 31.0) ** 2
            values.append(int(round(60000 * math.exp(-d2 / (2 * 36.0)))))
raw = struct.pack("<%dH" % len(values), *values)
header = (
    "NRRD0004\n# volref reference data: a Gaussian blob (scripts/make_reference_data.py)\n"
    "type: unsigned short\ndimension: 3\nsizes: 32 32 32\nspacings: 1 1 2\n"
    "endian: little\nencoding: gzip\n\n"
)
out = os.path.join(os.path.dirname(__file__), "..", "reference_scenes", "data", "gaussian.nrrd")
with open(out, "wb") as f:
    f.write(header.encode("ascii"))
    f.write(gzip.compress(raw, mtime=0))
print(out)
