#include "geometry/ClipPlanes.h"

#include <glm/geometric.hpp>

namespace volref {

void clip_intervals(const Ray& ray, const std::vector<ClipPlaneSpec>& planes, std::vector<Interval>& intervals) {
    for (const ClipPlaneSpec& p : planes) {
        const double f0 = glm::dot(ray.origin - p.point, p.normal);
        const double f1 = glm::dot(ray.direction, p.normal);
        if (f1 == 0.0) {
            if (!(f0 >= 0.0)) intervals.clear();
            continue;
        }
        const double t = -f0 / f1;
        for (Interval& iv : intervals) {
            if (f1 > 0.0)
                iv.t0 = std::max(iv.t0, t);
            else
                iv.t1 = std::min(iv.t1, t);
        }
        std::erase_if(intervals, [](const Interval& iv) { return !(iv.t1 > iv.t0); });
    }
}

}  // namespace volref
