// Writing a Volume as an attached-header NRRD file (NRRD0004), readable by read_volume / read_nrrd:
//
//   NRRD0004
//   # <comment lines>
//   type: uchar | signed char | ushort | short | uint | int | float | double
//   dimension: 3
//   space dimension: 3
//   sizes: nx ny nz
//   space directions: (sx,0,0) (0,sy,0) (0,0,sz)
//   kinds: domain domain domain
//   endian: little            (types of more than one byte)
//   encoding: raw | gzip
//   space origin: (ox,oy,oz)
//   <key>:=<value>
//   <blank line, then the samples, i fastest, little endian>
//
// Numbers in the header are written with the fewest digits that read back as the same double, so
// spacing and origin round-trip exactly. Values are written in `type` (VoxelEncoding.h): f64 round-trips
// exactly; f32 rounds each value to the nearest float (a finite value beyond the float range is an
// error; NaN and infinities are kept); an integer type takes integers in its range only (else an error).
// Key/value values are escaped as the NRRD format says ('\' as "\\", newline as "\n").
// The file is written to ".NAME.volref-tmp-PID.nrrd" in the output's folder and renamed into place,
// so a failure never leaves a partial file under the requested name.
#pragma once
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/grid/Volume.h"

namespace volref {

struct NrrdWriteOptions {
    enum class Encoding { Raw, Gzip };
    ScalarType type = ScalarType::F64;  // any of the 8 storage types
    Encoding encoding = Encoding::Raw;
    std::vector<std::string> comments;                             // one line each, without the '#'
    std::vector<std::pair<std::string, std::string>> key_values;  // written as key:=value
};

// Throws volref::Error unless `path` ends in .nrrd (any case) and its folder exists and is writable.
void check_nrrd_output_path(const std::filesystem::path& path);

// Throws volref::Error (one line starting with the path) on a bad path, an invalid volume (dims < 1,
// value count, non-finite origin, spacing not finite and > 0), a key with ":=" or a newline, a value
// the type cannot hold, or a failed write.
void write_nrrd(const Volume& volume, const std::filesystem::path& path, const NrrdWriteOptions& options = {});

}  // namespace volref
