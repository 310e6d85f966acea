// A brick of a volume file read as a sub-box: the header is parsed by volref's own reader of the
// format (core/io/VolumeLayout.h: NRRD, MetaImage, NIfTI, raw + JSON sidecar), then only the brick's
// rows are read (one seek and read per row). Compressed or otherwise not directly addressable data
// (gzip, ascii, a line skip, a flipped or permuted NIfTI orientation) and the formats without a
// layout (vtk, vti, den) are a one-line error naming the file.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "core/grid/Volume.h"
#include "core/io/VolumeLayout.h"

namespace volref::mpi {

// The layout of `path` (format "" = from the extension), without reading any sample; an Error when its
// samples cannot be read as a sub-box.
VolumeLayout read_volume_header(const std::filesystem::path& path, const std::string& format);

// Voxels lo .. lo + dims - 1 of the file (checked against the memory limit before reading). The
// layout's origin and spacing are the volume's (the scene's overrides applied).
Volume read_brick(const VolumeLayout& h, const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& dims);

}  // namespace volref::mpi
