// CompositeIntegrator: emission-absorption compositing (conventions sections 3 to 5).
//
// Segment k (midpoint value v_k, length d_k) has opacity a_k = a(v_k), colour c_k = c(v_k), optical
// depth tau_k = -(d_k / l) log1p(-a_k) and opacity alpha_k = -expm1(-tau_k).
//   front to back: C += T alpha_k c_k with T = exp(-tau), tau = the compensated sum of the tau_j in
//                  front of k (never a product of (1 - alpha));
//   back to front: C = alpha_k c_k + (1 - alpha_k) C, visiting the same segments from the far end.
// Both give A = -expm1(-tau_total) (1 where a segment has a = 1, which makes everything behind it
// invisible). The pixel is (C, A), premultiplied, accumulated in double.
// Early termination (front to back only): stop after the segment where A first exceeds the threshold.
#pragma once
#include "core/integrate/Integrator.h"

namespace volref {

class CompositeIntegrator final : public Integrator {
public:
    using Integrator::Integrator;
    PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const override;

private:
    PixelValue front_to_back(const Ray& ray, const std::vector<Interval>& intervals) const;
    PixelValue back_to_front(const Ray& ray, const std::vector<Interval>& intervals) const;
};

}  // namespace volref
