#!/usr/bin/env python3
"""Makes the tetrahedral bounds of the reference scenes (volume.bounds type "tetrahedra"), as VTK legacy
ASCII UNSTRUCTURED_GRID files in reference_scenes/data/: the shapes of OpenGL Volumizer's guide
(../shared/notes/volumizer.md A3; seed 003):

  tetra-box.vtk        Volumizer's cube of five tetrahedra: its vertex order (vtxData) and its
                       cubeIndices {0,2,5,7}, {3,2,0,7}, {1,2,5,0}, {2,7,6,5}, {5,4,0,7} as written
                       (seed L1730-1738; all five negative under VTK's right-hand rule), on the cube [10, 53]^3. Legacy
                       layout (CELLS n size, "4 i j k l" records), version 2.0 as Gmsh and TetGen write.
  tetra-icosphere.vtk  a sphere as a tessellated icosahedron: the icosahedron subdivided once (each
                       face into 4, new vertices pushed out to the sphere: 42 vertices, 80 faces), one
                       tetrahedron from the centre to each face; centre (32, 32, 32), radius 26.
  tetra-shell.vtk      the space between two such shells (radii 14 and 28, centre the origin): each face's
                       prism between the shells cut into 3 tetrahedra by the vertex-order rule (the
                       diagonal of each side quad starts at its lower-numbered outer vertex), so
                       neighbouring prisms share their faces; 240 tetrahedra. Version 5.1 layout
                       (OFFSETS and CONNECTIVITY arrays), as VTK 9 and ParaView write.

Coordinates are written with 17 significant digits (as double: they read back exactly). numpy only.
Regenerate with: /usr/bin/python3 scripts/make_tetrahedra.py"""
import os

import numpy as np

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "reference_scenes", "data")


def icosahedron():
    """The unit icosahedron: 12 vertices, 20 faces, counter-clockwise seen from outside."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    v = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0],
                  [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=float)
    v /= np.linalg.norm(v, axis=1)[:, None]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
         [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
         [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
         [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    return v, f


def subdivide(v, f):
    """Each face into 4; the edge midpoints pushed out to the unit sphere (shared between faces)."""
    verts = [p for p in v]
    mid = {}

    def midpoint(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            m = (verts[a] + verts[b]) / 2.0
            verts.append(m / np.linalg.norm(m))
            mid[key] = len(verts) - 1
        return mid[key]

    out = []
    for a, b, c in f:
        ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
        out += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
    return np.array(verts), out


def number(x):
    s = repr(float(x))
    return s[:-2] if s.endswith(".0") else s


def points_text(points):
    lines = ["POINTS %d double" % len(points)]
    lines += [" ".join(number(c) for c in p) for p in points]
    return lines


def write_legacy(name, title, points, tets):
    lines = ["# vtk DataFile Version 2.0", title, "ASCII", "DATASET UNSTRUCTURED_GRID"]
    lines += points_text(points)
    lines.append("CELLS %d %d" % (len(tets), 5 * len(tets)))
    lines += ["4 %d %d %d %d" % tuple(t) for t in tets]
    lines.append("CELL_TYPES %d" % len(tets))
    lines += ["10"] * len(tets)
    save(name, lines)


def write_51(name, title, points, tets):
    lines = ["# vtk DataFile Version 5.1", title, "ASCII", "DATASET UNSTRUCTURED_GRID"]
    lines += points_text(points)
    lines.append("CELLS %d %d" % (len(tets) + 1, 4 * len(tets)))
    lines.append("OFFSETS vtktypeint64")
    lines.append(" ".join(str(4 * k) for k in range(len(tets) + 1)))
    lines.append("CONNECTIVITY vtktypeint64")
    lines += ["%d %d %d %d" % tuple(t) for t in tets]
    lines.append("CELL_TYPES %d" % len(tets))
    lines += ["10"] * len(tets)
    save(name, lines)


def save(name, lines):
    path = os.path.join(OUT, name)
    with open(path, "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    print(os.path.normpath(path))


def box():
    lo, hi = 10.0, 53.0
    # Volumizer's vtxData order: 0 (0,0,0), 1 (X,0,0), 2 (X,Y,0), 3 (0,Y,0), 4 (0,0,Z), 5 (X,0,Z),
    # 6 (X,Y,Z), 7 (0,Y,Z).
    corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    points = [[lo + (hi - lo) * c for c in p] for p in corners]
    cube_indices = [[0, 2, 5, 7], [3, 2, 0, 7], [1, 2, 5, 0], [2, 7, 6, 5], [5, 4, 0, 7]]
    write_legacy("tetra-box.vtk", "Volumizer's cube of five tetrahedra (cubeIndices), [10, 53]^3 (scripts/make_tetrahedra.py)",
                 points, cube_indices)


def icosphere():
    v, f = subdivide(*icosahedron())
    centre, radius = np.array([32.0, 32.0, 32.0]), 26.0
    points = [centre] + [centre + radius * p for p in v]
    tets = [[0, a + 1, b + 1, c + 1] for a, b, c in f]
    write_legacy("tetra-icosphere.vtk",
                 "a sphere: a once-subdivided icosahedron, a tetrahedron from the centre to each face (scripts/make_tetrahedra.py)",
                 points, tets)


def shell():
    v, f = subdivide(*icosahedron())
    centre, r0, r1 = np.array([0.0, 0.0, 0.0]), 14.0, 28.0
    n = len(v)
    points = [centre + r1 * p for p in v] + [centre + r0 * p for p in v]  # outer i, inner i + n
    tets = []
    for face in f:
        a, b, c = sorted(face)
        a_, b_, c_ = a + n, b + n, c + n
        # The prism (a, b, c | a', b', c') with a < b < c: the side quad of edge (x, y), x < y, is cut
        # along x-y', whichever prism it belongs to.
        tets += [[a, b, c, c_], [a, b, b_, c_], [a, a_, b_, c_]]
    write_51("tetra-shell.vtk",
             "the space between two icosphere shells, radii 14 and 28, 3 tetrahedra per prism (scripts/make_tetrahedra.py)",
             points, tets)


if __name__ == "__main__":
    box()
    icosphere()
    shell()
