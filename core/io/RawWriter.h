// Writing a Volume as raw samples with a JSON sidecar (docs/formats.md), readable by read_volume:
// PATH holds the samples (i fastest, little endian; gzip-compressed when asked) and PATH.json says
//   {"dims": [nx, ny, nz], "type": "u16", "endian": "little", "origin": [..], "spacing": [..],
//    "header_bytes": 0, "encoding": "raw" | "gzip"}
// with origin and spacing written with the fewest digits that read back as the same doubles.
// Every value must be representable in the chosen type: integer types need whole numbers within the
// type's range, f32 rounds to the nearest float (a finite value beyond its range is an error), f64 is
// exact. Both files are written under temporary names in the output's folder and renamed into place,
// the data file first; a failure leaves neither.
#pragma once
#include <filesystem>

#include "core/grid/Volume.h"

namespace volref {

struct RawWriteOptions {
    ScalarType type = ScalarType::F64;
    bool gzip = false;
};

// Throws volref::Error (one line starting with the path) unless `path` ends in .raw and its folder is
// writable, on an invalid volume, a value the type cannot hold, or a failed write.
void write_raw(const Volume& volume, const std::filesystem::path& path, const RawWriteOptions& options = {});

}  // namespace volref
