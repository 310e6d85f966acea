// Reading raw sample files described by a JSON sidecar: for data file X the sidecar is X + ".json"
// (head.raw -> head.raw.json), e.g.
//   {"dims": [256, 256, 128], "type": "u16", "endian": "big", "origin": [0, 0, 0],
//    "spacing": [0.5, 0.5, 1.0], "header_bytes": 0, "encoding": "raw"}
// dims and type are required; docs/formats.md describes every key and error.
#pragma once
#include <filesystem>

#include "core/grid/Volume.h"

namespace volref {

// Errors are volref::Error with a one-line message starting with the path of the file at fault: the
// sidecar for its keys ("head.raw.json: spacing[1]: expected a number > 0, got -1"), the data file
// for its contents.
Volume read_raw_volume(const std::filesystem::path& path);

}  // namespace volref
