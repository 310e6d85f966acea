// TetrahedralMesh: a set of tetrahedra bounding a volume (scene key volume.bounds with type
// "tetrahedra"): OpenGL Volumizer's geometry, voIndexedTetraSet ("a collection of tetrahedra ... defines
// a solid shape"; ../shared/notes/volumizer.md A3).
//
// File (read_tetrahedra): VTK legacy (.vtk), `DATASET UNSTRUCTURED_GRID`, ASCII or BINARY (big-endian),
// the format VTK, ParaView, Gmsh, TetGen and meshio write for tetrahedral meshes, and the family of the
// VTK legacy images volref already reads (core/io/VtkLegacyReader.h):
//   # vtk DataFile Version x.y | title | ASCII or BINARY        (lines 1 to 3)
//   DATASET UNSTRUCTURED_GRID
//   POINTS n float|double                                        3 n coordinates
//   CELLS n size       then n records "4 i j k l"                (versions up to 4.2)
//   CELLS n+1 m        then OFFSETS type, n+1 offsets, CONNECTIVITY type, m indices   (version 5.1)
//   CELL_TYPES n       every one 10 (VTK_TETRA)
//   POINT_DATA / CELL_DATA ...                                   (ignored: they end the geometry)
// Keywords are not case-sensitive, FIELD and METADATA blocks are skipped, and the sections may come in
// any order. ASCII float coordinates are rounded to float (as VTK holds them); BINARY ones are exact.
//
// Every tetrahedron must have a volume: |det(b - a, c - a, d - a)| > kTetrahedronDegenerateRelative
// l^3 (core/Conventions.h; l its longest edge). Orientation is a convention of the writer (VTK's
// right-hand rule gives det > 0; Volumizer's cubeIndices are all det < 0), so either is accepted,
// mixed too: each tetrahedron is oriented positively (det > 0, points 2 and 3 swapped if not). Refused, each with one line naming the file and
// the line (ASCII) or byte (BINARY) and the cell or point index: degenerate tetrahedra, point indices
// out of range, coordinates that are not finite or beyond 1e100, cell types other than 10, cells
// without 4 points, counts that do not match (CELL_TYPES against CELLS, the sizes of CELLS, OFFSETS
// against CONNECTIVITY), truncated data, a file with no tetrahedra, and a file larger than the memory
// limit (core/InputFile.h check_whole_file, before it is read).
//
// The region (tetrahedra_boundary): the union of the tetrahedra. Its boundary is the set of faces
// not cancelled by the same face of another tetrahedron in the opposite orientation: for a conforming
// tessellation, the faces used by exactly one tetrahedron, outward; a face two tetrahedra hold on the
// same side (overlapping tetrahedra) stays twice. With every tetrahedron positive, these triangles are
// a closed surface (Closedness::Cycle: every edge used as often each way) whose winding number at a
// point is the number of tetrahedra covering it, so the closed-mesh path (geometry/MeshIntervals.h,
// winding > 0) gives exactly the union. Vertices at exactly the same position are merged first, so
// files that repeat points per cell still share their faces.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "geometry/TriangleMesh.h"

namespace volref {

struct TetrahedralMesh {
    std::vector<glm::dvec3> vertices;
    std::vector<std::array<std::uint32_t, 4>> tetrahedra;  // indices into vertices
};

// det(b - a, c - a, d - a): 6 x the signed volume of (a, b, c, d).
double tetrahedron_det(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d);

// Reads a VTK legacy UNSTRUCTURED_GRID of tetrahedra (above), checks it and orients every tetrahedron
// positively. Errors are volref::Error one-liners starting with the path.
TetrahedralMesh read_tetrahedra(const std::string& path);

// The checks of read_tetrahedra for a set made in memory: indices in range, finite vertices within
// 1e100, no degenerate tetrahedron; orients each positively. Errors: "NAME: tetrahedron K ...".
void orient_tetrahedra(TetrahedralMesh& mesh, const std::string& name);

struct TetrahedralBoundary {
    TriangleMesh surface;            // the boundary triangles, outward; vertices merged, unused ones dropped
    std::size_t internal_faces = 0;  // faces cancelled in pairs (a face shared by two tetrahedra counts once)
};

// The boundary of the union of `mesh`'s tetrahedra (above). The tetrahedra must be non-degenerate (as
// read_tetrahedra and orient_tetrahedra leave them); their orientation is taken from det's sign.
TetrahedralBoundary tetrahedra_boundary(const TetrahedralMesh& mesh);

// read_tetrahedra + tetrahedra_boundary + check_closed (Closedness::Cycle): the surface a scene's
// bounds hand to BoundingGeometry::add_mesh.
TriangleMesh read_tetrahedral_bounds(const std::string& path);

// Sum of the tetrahedra's |volume|.
double tetrahedra_volume(const TetrahedralMesh& mesh);

}  // namespace volref
