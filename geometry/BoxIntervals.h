// The intervals of many rays in one box shape at once, on SIMD lanes (BoxIntervals.cpp).
#pragma once
#include <vector>

#include "core/camera/Ray.h"
#include "geometry/RayIntervals.h"

namespace volref {

// A box shape: the box [lo, hi] and the volume's domain [domain_lo, domain_hi] (`is_domain`: the same).
struct BoxShapeBounds {
    double lo[3] = {}, hi[3] = {};
    double domain_lo[3] = {}, domain_hi[3] = {};
    bool is_domain = false;
};

// Appends to out[i] the interval of rays[i] in the box AND the domain AND t >= 0 (box_shape_lanes,
// BoxIntersection-inl.h), where it is not empty; as box_interval does ray by ray.
void box_shape_intervals(const BoxShapeBounds& box, const Ray* rays, int count, std::vector<Interval>* out);

}  // namespace volref
