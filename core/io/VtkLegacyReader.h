// Reading VTK legacy files (.vtk) holding STRUCTURED_POINTS into a Volume:
//   # vtk DataFile Version x.y        (line 1)
//   TITLE                             (line 2, any text)
//   ASCII | BINARY                    (line 3)
//   DATASET STRUCTURED_POINTS
//   DIMENSIONS nx ny nz               (these three in any order)
//   SPACING sx sy sz                  (or ASPECT_RATIO; default 1 1 1)
//   ORIGIN x y z                      (default 0 0 0)
//   POINT_DATA n                      (n = nx * ny * nz)
//   SCALARS name type [1]             (type: unsigned_char, char, unsigned_short, short, unsigned_int,
//   LOOKUP_TABLE name                  int, float, double; one component)
//   samples: ASCII numbers, or BINARY big-endian right after the LOOKUP_TABLE line's end
// Keywords are not case-sensitive. docs/formats.md lists every error.
#pragma once
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

#include "core/grid/Volume.h"

namespace volref {

Volume read_vtk_legacy(const std::filesystem::path& path);

// Lines 1..3 of any VTK legacy file (the version line, the title, ASCII | BINARY): the byte just after
// line 3 and whether the data are BINARY; throws volref::Error naming `where` and the line. Also read by
// geometry/TetrahedralMesh (UNSTRUCTURED_GRID).
std::pair<std::size_t, bool> read_vtk_legacy_preamble(std::string_view file, const std::string& where);

}  // namespace volref
