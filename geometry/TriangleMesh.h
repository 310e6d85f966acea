// TriangleMesh: a closed triangle mesh bounding a volume (scene key volume.bounds with type "mesh").
//
// Loading (read_mesh): .obj through tinyobjloader (its double-precision build: coordinates are read
// as double; polygons are triangulated by tinyobjloader), .ply by volref's own reader (geometry/PlyReader.h:
// ASCII and binary, coordinates exact as double, polygons fanned; assimp was replaced after fuzzing
// found it aborting, hanging and exhausting memory on malformed files). Vertices at exactly the same position are
// merged, so files that repeat a vertex per face (as many exporters do) still form closed meshes.
// Points and lines in the file are ignored. Errors are volref::Error one-liners naming the file.
//
// Closedness (check_closed): every undirected edge is used by exactly two triangles, in opposite
// directions (a consistently oriented, closed 2-manifold edge structure); triangles with a repeated
// vertex (after merging) bound nothing and are removed; triangles of zero area with three distinct
// vertices are kept (they are part of the edge structure; the ray test of geometry/MeshIntervals.h
// crosses them only where rounding leaves their projection a sliver of area, consistently with
// their neighbours).
// The mesh is then oriented outward: if its signed volume is negative every triangle is flipped.
// A closed mesh with zero signed volume is an error.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace volref {

struct TriangleMesh {
    std::vector<glm::dvec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into vertices
};

// Reads an .obj or .ply file (by extension, case-insensitive) and merges coincident vertices.
// Does not check closedness: see check_closed (or read_closed_mesh for both).
TriangleMesh read_mesh(const std::string& path);

// Merges vertices at exactly the same position (keeping the first occurrence's place) and drops
// vertices no triangle uses; triangle indices are remapped.
void merge_coincident_vertices(TriangleMesh& mesh);

// What check_closed asks of the edges.
//   Manifold: every undirected edge is used by exactly two triangles, in opposite directions (a mesh
//             file: a closed, consistently oriented 2-manifold).
//   Cycle:    every undirected edge is used as often in one direction as in the other (a closed
//             surface that may touch itself along an edge or at a vertex, or run twice over a face:
//             the boundary of a set of tetrahedra, geometry/TetrahedralMesh.h). The ray test's
//             winding number is well defined for it all the same (geometry/MeshIntervals.h).
enum class Closedness { Manifold, Cycle };

// Throws Error "NAME: the mesh is not closed (...)" / "NAME: the mesh is not consistently oriented (...)"
// naming the first offending edge by its vertices' positions; otherwise removes triangles with a
// repeated vertex and orients the mesh outward (positive signed volume). `name` is usually the file.
void check_closed(TriangleMesh& mesh, const std::string& name, Closedness rule = Closedness::Manifold);

// read_mesh + check_closed.
TriangleMesh read_closed_mesh(const std::string& path);

// Sum over triangles of det(a - r, b - r, c - r) / 6 with r the first vertex: the enclosed volume,
// positive for an outward-oriented closed mesh.
double signed_volume(const TriangleMesh& mesh);

}  // namespace volref
