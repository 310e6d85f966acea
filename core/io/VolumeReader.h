// Reading volume files: one entry point, the format from the extension or given explicitly.
//   .nrrd, .nhdr  NRRD (attached or detached header; raw or gzip encodings; every scalar type of
//                 conventions section 1; either endianness; spacings or axis-aligned space directions)
//   .raw          raw samples described by a JSON sidecar PATH.json (docs/formats.md)
// Errors are volref::Error with a one-line message that starts with the file's path.
#pragma once
#include <filesystem>
#include <string>

#include "core/grid/Volume.h"

namespace volref {

// format: "" (from the extension), "nrrd" or "raw".
Volume read_volume(const std::filesystem::path& path, const std::string& format = "");

}  // namespace volref
