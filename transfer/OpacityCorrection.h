// The emission-absorption optical model's two formulas (conventions section 3).
//
// A transfer-function opacity a is the opacity accumulated over the unit distance l.
//   extinction       sigma = -ln(1 - a) / l                    = -log1p(-a) / l
//   segment opacity  alpha_d = 1 - (1 - a)^(d / l)             = -expm1((d / l) * log1p(-a))
// expm1/log1p keep small a and small d accurate. a = 1 is opaque: sigma = +inf, alpha_d = 1 for d > 0.
// A segment of length 0 has alpha 0 whatever a is.
#pragma once
#include <cmath>

#include "core/Lanes.h"

namespace volref {

// optical_depth<L> and segment_alpha<L>, for every lane type.
#include "transfer/OpacityCorrection-inl.h"

inline double extinction(double a, double unit_distance) { return -std::log1p(-a) / unit_distance; }

// The segment's optical depth sigma d = -(d / l) log1p(-a) (+inf for a = 1); alpha_d = -expm1(-sigma d).
inline double optical_depth(double a, double d, double unit_distance) { return optical_depth<Scalar>(a, d, unit_distance); }

inline double opacity_for_length(double a, double d, double unit_distance) {
    if (d <= 0.0) return 0.0;
    if (a >= 1.0) return 1.0;
    return segment_alpha<Scalar>(optical_depth(a, d, unit_distance));
}

}  // namespace volref
