// The slab test in double precision: the interval of t where origin + t * direction lies in the
// closed box [lo, hi]. On an axis where the direction is exactly 0 the slab holds for every t if
// lo <= origin <= hi and for none otherwise (no 0 * inf). Returns false when the interval is empty.
#pragma once
#include <algorithm>
#include <limits>
#include <utility>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "geometry/RayIntervals.h"

namespace volref {

// One axis' slab lo <= o + t d <= hi: [ta, tb] (ta <= tb); for d = 0 the whole line or nothing
// (returns false when o is outside [lo, hi]; ta = -inf, tb = +inf otherwise).
inline bool intersect_slab(double o, double d, double lo, double hi, double& ta, double& tb) {
    if (d == 0.0) {
        ta = -std::numeric_limits<double>::infinity();
        tb = std::numeric_limits<double>::infinity();
        return !(o < lo || o > hi);
    }
    ta = (lo - o) / d;
    tb = (hi - o) / d;
    if (ta > tb) std::swap(ta, tb);
    return true;
}

inline bool intersect_box(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi, Interval& out) {
    double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        double ta, tb;
        if (!intersect_slab(ray.origin[a], ray.direction[a], lo[a], hi[a], ta, tb)) return false;
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (!(t0 <= t1)) return false;
    out = {t0, t1};
    return true;
}

}  // namespace volref
