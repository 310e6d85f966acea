// PlyReader: bounding meshes from PLY files (ASCII, binary little- and big-endian), read by volref
// itself. (assimp 5.2, Debian 12's PLY reader, aborts, loops forever or allocates without bound on
// malformed files: found by fuzz_ply, docs/robustness.md; its inputs are kept in
// tests/fuzz/regressions/fuzz_ply/.)
//
// Accepted header:
//   ply / format ascii|binary_little_endian|binary_big_endian 1.0 / comment ... / obj_info ...
//   element vertex N   scalar properties only, among them x, y and z
//   element face M     scalar properties and exactly one list property vertex_indices (or vertex_index)
//   other elements     scalar properties only (read and ignored)
//   end_header
// Types char uchar short ushort int uint float double (and int8 .. float64). Coordinates are read as
// double from their stored type (exact). A face of n >= 3 indices becomes the fan (v0, vk, vk+1);
// faces of fewer indices bound nothing and are skipped. Every count is checked against the bytes
// left in the file before anything is allocated; every index against the vertex count. Errors name
// the file and the header line, element or face at fault.
#pragma once
#include <string>

#include "geometry/TriangleMesh.h"

namespace volref {

TriangleMesh read_ply_mesh(const std::string& path);

}  // namespace volref
