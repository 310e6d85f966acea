// The slab test in double precision: the interval of t where origin + t * direction lies in the
// closed box [lo, hi]. On an axis where the direction is exactly 0 the slab holds for every t if
// lo <= origin <= hi and for none otherwise (no 0 * inf). Returns false when the interval is empty.
// The arithmetic is BoxIntersection-inl.h's lane templates, shared with the packets (BoxIntervals.cpp).
#pragma once
#include <algorithm>
#include <limits>
#include <utility>

#include <glm/vec3.hpp>

#include "core/Lanes.h"
#include "core/camera/Ray.h"
#include "geometry/RayIntervals.h"

namespace volref {

#include "geometry/BoxIntersection-inl.h"

// One axis' slab lo <= o + t d <= hi: [ta, tb] (ta <= tb); for d = 0 the whole line or nothing
// (returns false when o is outside [lo, hi]; ta = -inf, tb = +inf otherwise).
inline bool intersect_slab(double o, double d, double lo, double hi, double& ta, double& tb) {
    return slab_lanes<Scalar>(o, d, lo, hi, ta, tb);
}

inline bool intersect_box(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi, Interval& out) {
    const double o[3] = {ray.origin.x, ray.origin.y, ray.origin.z}, d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    double t0, t1;
    if (!box_lanes<Scalar>(o, d, l, h, t0, t1)) return false;
    out = {t0, t1};
    return true;
}

}  // namespace volref
