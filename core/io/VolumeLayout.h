// Where a volume file's samples lie, from its header alone (no sample is read): for readers of a part
// of a volume, such as volref-mpi's bricks (cli/mpi/BrickReader.h), which seek to each row of a
// sub-box. Each reader's own header parser fills it (NrrdReader.cpp, MetaImageReader.cpp,
// NiftiReader.cpp, RawReader.cpp), with the same checks and messages as reading the whole volume.
#pragma once
#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <string>

#include <glm/vec3.hpp>

#include "core/grid/VoxelArray.h"

namespace volref {

struct VolumeLayout {
    std::array<std::int64_t, 3> dims{1, 1, 1};  // volume axes (x fastest in the file)
    glm::dvec3 origin{0.0}, spacing{1.0};
    ScalarType type = ScalarType::U8;  // as stored
    std::endian endian = std::endian::little;
    std::filesystem::path data;  // the file holding the samples
    std::string data_where;      // how messages name it (the path, or "PATH (data file of HEADER)")
    std::uint64_t offset = 0;    // the byte of voxel (0, 0, 0) in `data`
    // Empty when the samples are stored uncompressed, one after the other in the volume's order
    // (x fastest) from `offset`, so that any voxel is at offset + index * size. Otherwise why not
    // ("gzip encoding", "ascii encoding", "line skip", "a flipped or permuted orientation").
    std::string not_direct;
    // NIfTI's scl_slope / scl_inter: when `scaled`, value = slope * stored + inter (as f64).
    bool scaled = false;
    double slope = 1.0, inter = 0.0;
};

// The offset of samples that end the data file (a header's "skip -1"): file size - bytes, after
// checking that the file holds `bytes` beyond `base` (else the readers' truncation Error).
std::uint64_t trailing_samples_offset(const VolumeLayout& layout, std::uint64_t base, std::uint64_t bytes);

VolumeLayout nrrd_layout(const std::filesystem::path& path);
VolumeLayout metaimage_layout(const std::filesystem::path& path);
VolumeLayout nifti_layout(const std::filesystem::path& path);
VolumeLayout raw_layout(const std::filesystem::path& path);

// The layout of `path` in `format` ("" = from the extension, as read_volume). Formats without a layout
// (vtk, vti, den) are an Error naming the file.
VolumeLayout volume_layout(const std::filesystem::path& path, const std::string& format = "");

}  // namespace volref
