// Reading NRRD files (teem's format, magic NRRD0001 to NRRD0005) into a Volume: attached headers
// (.nrrd, data after the blank line that ends the header) and detached ones (.nhdr, `data file:`
// naming the data); raw, gzip and ascii encodings; the 8 scalar types of Volume in either byte
// order; 1 to 3 axes; spacing from `spacings` or axis-aligned `space directions`, origin from
// `space origin`. docs/formats.md lists what is accepted and every error.
#pragma once
#include <filesystem>

#include "core/grid/Volume.h"

namespace volref {

// Errors are volref::Error with a one-line message starting with the path of the file at fault
// (the header, or the data file a detached header names).
Volume read_nrrd(const std::filesystem::path& path);

}  // namespace volref
