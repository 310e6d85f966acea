// A summary of a volume for `volref info`: value range and a histogram of the finite values.
//
// Histogram: `bins` equal bins over [min, max] of the finite values; value v goes to bin
// floor((v - min) / (max - min) * bins), the maximum to the last bin. When min == max every finite
// value is in bin 0. NaN and infinite values are counted apart, not binned.
#pragma once
#include <cstdint>
#include <vector>

#include "core/grid/Volume.h"

namespace volref {

struct VolumeSummary {
    std::uint64_t voxels = 0;
    std::uint64_t finite = 0;
    std::uint64_t nan = 0;
    std::uint64_t infinite = 0;
    double min = 0.0, max = 0.0;  // over the finite values (0, 0 when there are none)
    std::vector<std::uint64_t> histogram;
};

// bins >= 1.
VolumeSummary summarize(const Volume& volume, int bins);

}  // namespace volref
