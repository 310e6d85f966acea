#include "core/grid/Volume.h"

#include <algorithm>
#include <limits>

#include <sys/mman.h>

#include "core/Error.h"
#include "core/MemoryLimit.h"

namespace volref {

const char* scalar_type_name(ScalarType t) {
    switch (t) {
        case ScalarType::U8: return "u8";
        case ScalarType::I8: return "i8";
        case ScalarType::U16: return "u16";
        case ScalarType::I16: return "i16";
        case ScalarType::U32: return "u32";
        case ScalarType::I32: return "i32";
        case ScalarType::F32: return "f32";
        case ScalarType::F64: return "f64";
    }
    return "?";
}

std::size_t scalar_type_size(ScalarType t) {
    switch (t) {
        case ScalarType::U8: case ScalarType::I8: return 1;
        case ScalarType::U16: case ScalarType::I16: return 2;
        case ScalarType::U32: case ScalarType::I32: case ScalarType::F32: return 4;
        case ScalarType::F64: return 8;
    }
    return 0;
}

bool scalar_type_is_integer(ScalarType t) { return t != ScalarType::F32 && t != ScalarType::F64; }

std::array<double, 2> scalar_type_range(ScalarType t) {
    switch (t) {
        case ScalarType::U8: return {0.0, 255.0};
        case ScalarType::I8: return {-128.0, 127.0};
        case ScalarType::U16: return {0.0, 65535.0};
        case ScalarType::I16: return {-32768.0, 32767.0};
        case ScalarType::U32: return {0.0, 4294967295.0};
        case ScalarType::I32: return {-2147483648.0, 2147483647.0};
        case ScalarType::F32: return {-double(std::numeric_limits<float>::max()), double(std::numeric_limits<float>::max())};
        case ScalarType::F64: return {std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max()};
    }
    return {0.0, 0.0};
}

std::array<double, 2> Volume::value_range() const {
    if (whole_range) return *whole_range;
    if (values.empty()) return {0.0, 0.0};
    // One pass in the storage type (NaN compares false, as std::minmax_element's comparisons do).
    return values.visit([&](const auto* p) -> std::array<double, 2> {
        auto [lo, hi] = std::minmax_element(p, p + values.size());
        return {double(*lo), double(*hi)};
    });
}

std::size_t checked_voxel_count(const std::array<std::int64_t, 3>& dims, const std::string& what,
                                std::size_t bytes_per_value) {
    const std::size_t count = checked_voxel_count_unlimited(dims, what, bytes_per_value);
    check_memory(count * std::max<std::size_t>(bytes_per_value, 1),
                 what + ": a volume of " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                     std::to_string(dims[2]));
    return count;
}

std::size_t checked_voxel_count_unlimited(const std::array<std::int64_t, 3>& dims, const std::string& what,
                                          std::size_t bytes_per_value) {
    // The largest volume volref accepts: 2^38 bytes (256 GiB) of doubles; a later --max-memory may lower it.
    constexpr std::size_t kMaxBytes = std::size_t(1) << 38;
    std::size_t count = 1;
    for (int a = 0; a < 3; ++a) {
        if (dims[a] < 1)
            throw Error(what + ": dims must be >= 1 (got " + std::to_string(dims[a]) + " on axis " +
                        std::to_string(a) + ")");
        const auto d = static_cast<std::size_t>(dims[a]);
        if (count > std::numeric_limits<std::size_t>::max() / d)
            throw Error(what + ": dims " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                        std::to_string(dims[2]) + " overflow the voxel count");
        count *= d;
    }
    if (count > kMaxBytes / std::max<std::size_t>(bytes_per_value, 1))
        throw Error(what + ": dims " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                    std::to_string(dims[2]) + " need more than 256 GiB");
    return count;
}

void VoxelArray::advise_huge_pages(void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
    const auto begin = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t first = (begin + kHugePage - 1) / kHugePage * kHugePage, end = (begin + bytes) / kHugePage * kHugePage;
    if (first < end) (void)madvise(reinterpret_cast<void*>(first), end - first, MADV_HUGEPAGE);
#else
    (void)p, (void)bytes;
#endif
}

}  // namespace volref
