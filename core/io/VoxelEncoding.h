// Writing one voxel value in a storage type, little endian: the one encoder both volume writers
// (NrrdWriter, RawWriter) use. An integer type takes only integers in its range (exactly); f32 takes
// any finite value within the float range (rounded to the nearest float; NaN and infinities kept);
// f64 takes every value as it is.
#pragma once
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/grid/VoxelArray.h"

namespace volref {

// Writes x as `type` into out[0 .. scalar_type_size(type)); false (nothing usable written) when x
// is not representable in the type.
inline bool encode_voxel(double x, ScalarType type, unsigned char* out) {
    const std::size_t size = scalar_type_size(type);
    std::uint64_t bits = 0;
    if (scalar_type_is_integer(type)) {
        const auto [lo, hi] = scalar_type_range(type);
        if (!(x >= lo && x <= hi && std::floor(x) == x)) return false;
        bits = static_cast<std::uint64_t>(static_cast<std::int64_t>(x));
    } else if (type == ScalarType::F32) {
        if (std::isfinite(x) && std::fabs(x) > double(std::numeric_limits<float>::max())) return false;
        bits = std::bit_cast<std::uint32_t>(static_cast<float>(x));
    } else {
        bits = std::bit_cast<std::uint64_t>(x);
    }
    for (std::size_t b = 0; b < size; ++b) out[b] = static_cast<unsigned char>((bits >> (8 * b)) & 0xff);
    return true;
}

// What the message says when a value is not representable: "an integer in the range of u16",
// "in the range of f32".
inline std::string encodable_range(ScalarType type) {
    return std::string(scalar_type_is_integer(type) ? "an integer in the range of " : "in the range of ") +
           scalar_type_name(type);
}

}  // namespace volref
