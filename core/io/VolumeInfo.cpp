#include "core/io/VolumeInfo.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volref {

VolumeSummary summarize(const Volume& volume, int bins) {
    VolumeSummary s;
    s.voxels = volume.values.size();
    s.histogram.assign(std::size_t(std::max(bins, 1)), 0);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double v : volume.values) {
        if (std::isnan(v)) {
            ++s.nan;
        } else if (std::isinf(v)) {
            ++s.infinite;
        } else {
            ++s.finite;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    }
    if (s.finite == 0) return s;
    s.min = lo;
    s.max = hi;
    const double n = double(s.histogram.size());
    const double width = hi - lo;
    for (double v : volume.values) {
        if (!std::isfinite(v)) continue;
        std::size_t bin = 0;
        if (width > 0.0) {
            const double x = std::floor((v - lo) / width * n);
            bin = x >= n ? s.histogram.size() - 1 : std::size_t(std::max(x, 0.0));
        }
        ++s.histogram[bin];
    }
    return s;
}

}  // namespace volref
