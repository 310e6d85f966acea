// A brick of a volume file read as a sub-box (only the brick's rows are read: fseek + fread per row).
// raw + JSON sidecar (core/io/RawReader.h's format, "encoding": "raw") is supported; other formats
// give a one-line error naming what is not supported yet.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"

namespace volref::mpi {

struct VolumeHeader {
    std::array<std::int64_t, 3> dims{1, 1, 1};
    glm::dvec3 origin{0.0}, spacing{1.0};
    ScalarType type = ScalarType::F64;
    std::endian endian = std::endian::little;
    std::int64_t header_bytes = 0;
    std::filesystem::path data;
};

// The header of `path` (format "" = from the extension), without reading any sample.
VolumeHeader read_volume_header(const std::filesystem::path& path, const std::string& format);

// Voxels lo .. lo + dims - 1 of the file (checked against the memory limit before reading).
Volume read_brick(const VolumeHeader& h, const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& dims);

}  // namespace volref::mpi
