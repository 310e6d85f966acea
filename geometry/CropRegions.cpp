#include "geometry/CropRegions.h"

#include <algorithm>
#include <array>

namespace volref {

int crop_region(const CropSpec& crop, const glm::dvec3& p) {
    int region = 0, weight = 1;
    for (int a = 0; a < 3; ++a, weight *= 3) {
        const double lo = crop.planes[std::size_t(2 * a)], hi = crop.planes[std::size_t(2 * a + 1)];
        const int i = p[a] < lo ? 0 : (p[a] <= hi ? 1 : 2);
        region += i * weight;
    }
    return region;
}

void crop_intervals(const Ray& ray, const CropSpec& crop, std::vector<Interval>& intervals) {
    std::array<double, 6> cuts{};
    int n = 0;
    for (int a = 0; a < 3; ++a)
        if (ray.direction[a] != 0.0)
            for (int side = 0; side < 2; ++side)
                cuts[std::size_t(n++)] = (crop.planes[std::size_t(2 * a + side)] - ray.origin[a]) / ray.direction[a];
    std::sort(cuts.begin(), cuts.begin() + n);
    std::vector<Interval> out;
    for (const Interval& iv : intervals) {
        double t0 = iv.t0;
        for (int k = 0; k <= n; ++k) {
            const double t1 = k < n ? std::min(std::max(cuts[std::size_t(k)], iv.t0), iv.t1) : iv.t1;
            if (t1 > t0) {
                if (crop_keeps(crop, ray.at(t0 + 0.5 * (t1 - t0)))) {
                    if (!out.empty() && out.back().t1 == t0)
                        out.back().t1 = t1;
                    else
                        out.push_back({t0, t1});
                }
                t0 = t1;
            }
        }
    }
    intervals = std::move(out);
}

}  // namespace volref
