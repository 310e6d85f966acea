// The tolerance of a comparison, per pixel and channel (docs/compare.md, "Tolerance"):
//   tol(p, c) = T                                   (--tolerance T, default 0)
//             + e_A(p) + e_B(p)                     (--tolerance-from-error: each input's `error` channel)
//             + Q_A(p, c) + Q_B(p, c)               (each integer input's quantisation, CompareConstants.h)
// A pixel is over the tolerance when |A - B| > tol(p, c) in any compared channel.
#pragma once
#include <string>
#include <vector>

#include "core/compare/ComparedImage.h"

namespace volref::compare {

struct ToleranceSpec {
    double absolute = 0.0;         // T >= 0
    bool from_error = false;       // add the `error` channels (at least one input must have one)
};

// Quantisation bound of one integer input at pixel p, channel c (0 for a floating-point input):
// q = 0.5 / (2^bits - 1); unassociated colour q (a_s + u_s) + q^2, alpha q; otherwise q.
double quantisation_bound(const ComparedImage& image, std::size_t pixel, std::size_t channel);

// tol(p, c) for the 4 channels R, G, B, A, interleaved (width * height * 4). Throws volref::Error when
// from_error is asked and neither input has an `error` channel, or T is negative or not finite.
std::vector<double> tolerance_map(const ComparedImage& a, const ComparedImage& b, const ToleranceSpec& spec);

// One line saying what the tolerance is made of, e.g. "0.001 + error channel of A + 8-bit quantisation of B".
std::string describe_tolerance(const ComparedImage& a, const ComparedImage& b, const ToleranceSpec& spec);

}  // namespace volref::compare
