// Volume: a regular, vertex-centred scalar grid (conventions section 1).
//
// Voxel (i, j, k) holds the value at origin + (i*sx, j*sy, k*sz); the domain is the box
// [origin, origin + (dims - 1) * spacing]. Storage is i fastest, then j, then k. Values are kept in
// the file's type (VoxelArray: u8 .. u32, i8 .. i32, f32, f64, 1 to 8 bytes per voxel) and read as
// double, which is exact for every type, so reconstruction never re-rounds them. `type` is the
// file's type for the normalised domain; the readers store the values in that same type
// (values.type() == type); procedural fields, resampled grids and caches are f64.
#pragma once
#include <array>
#include <optional>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/grid/VoxelArray.h"

namespace volref {

struct Volume {
    std::array<std::int64_t, 3> dims{0, 0, 0};
    glm::dvec3 origin{0.0};
    glm::dvec3 spacing{1.0};
    ScalarType type = ScalarType::F64;
    VoxelArray values;  // dims[0] * dims[1] * dims[2] values, i fastest, in the storage type values.type()

    std::size_t index(std::int64_t i, std::int64_t j, std::int64_t k) const {
        return static_cast<std::size_t>(i + dims[0] * (j + dims[1] * k));
    }
    double at(std::int64_t i, std::int64_t j, std::int64_t k) const { return values[index(i, j, k)]; }
    // World position of voxel (i, j, k).
    glm::dvec3 voxel_position(std::int64_t i, std::int64_t j, std::int64_t k) const {
        return origin + glm::dvec3(double(i), double(j), double(k)) * spacing;
    }
    glm::dvec3 domain_min() const { return origin; }
    glm::dvec3 domain_max() const {
        return origin + glm::dvec3(double(dims[0] - 1), double(dims[1] - 1), double(dims[2] - 1)) * spacing;
    }
    // [min, max] of the stored values, or `whole_range` when set.
    std::array<double, 2> value_range() const;
    // The data range of the whole volume this one is a part of (volref-mpi's bricks, cli/mpi/): what
    // value_range() reports, so that the transfer function's default window and the shader's
    // zero-gradient tolerance (conventions §8) are the whole volume's on every rank. Unset otherwise.
    std::optional<std::array<double, 2>> whole_range;
    // A volume on the same grid (dims, origin, spacing), type f64, every value 0.
    Volume same_grid() const {
        Volume v;
        v.dims = dims;
        v.origin = origin;
        v.spacing = spacing;
        v.values.assign(values.size(), 0.0);
        return v;
    }
};

// Checks that every dim is >= 1 and that their product (and its size in bytes at `bytes_per_value`,
// the storage type's size) does not overflow, exceed 2^38 bytes or the memory limit; throws Error
// naming `what` otherwise. Returns the voxel count.
std::size_t checked_voxel_count(const std::array<std::int64_t, 3>& dims, const std::string& what,
                                std::size_t bytes_per_value = sizeof(double));
// The same checks without the memory limit: for a header whose samples are not all read here (a
// brick of the file is; core/io/VolumeLayout.h).
std::size_t checked_voxel_count_unlimited(const std::array<std::int64_t, 3>& dims, const std::string& what,
                                          std::size_t bytes_per_value = sizeof(double));

}  // namespace volref
