// Trilinear reconstruction in the corner order of Levoy's lecture (conventions section 2).
//
// For the unit cell with fractional position (p, q, r) and corner values f1..f8 at
//   f1 = (0,0,0), f2 = (1,0,0), f3 = (1,1,0), f4 = (0,1,0), f5..f8 the same at r = 1:
//   f = f1 (1-p)(1-q)(1-r) + f2 p(1-q)(1-r) + f3 p q (1-r) + f4 (1-p) q (1-r)
//     + f5 (1-p)(1-q) r     + f6 p(1-q) r     + f7 p q r     + f8 (1-p) q r.
// The sum is evaluated term by term in this order, so a hand calculation reproduces it bit for bit.
// The arithmetic is Trilinear-inl.h's lane templates (clamped_index, cell_of, trilinear_sum), shared
// with the SIMD packets; here the scalar lanes.
#pragma once
#include <array>

#include "core/Lanes.h"

namespace volref {

#include "core/sample/Trilinear-inl.h"

// The eight weights, in corner order f1..f8.
inline std::array<double, 8> trilinear_weights(double p, double q, double r) {
    const double P = 1.0 - p, Q = 1.0 - q, R = 1.0 - r;
    return {P * Q * R, p * Q * R, p * q * R, P * q * R, P * Q * r, p * Q * r, p * q * r, P * q * r};
}

// f at (p, q, r) from the corner values f1..f8.
inline double trilinear(const std::array<double, 8>& f, double p, double q, double r) {
    return trilinear_sum<Scalar>(f.data(), p, q, r);
}

}  // namespace volref
