// LineIntegralIntegrator: the average and x-ray projections (conventions section 6).
// With the midpoint samples of SamplePlacement.h, I = sum_k s(v_k) d_k (a compensated sum) and L = sum_k d_k,
// where s is the transfer function's coordinate (the data value, or the normalised value for the
// normalised domain):
//   average: g = I / L,          pixel (g, g, g, 1);
//   xray:    g = gain * I,       pixel (g, g, g, 1).
// A ray with no interval is (0, 0, 0, 0).
#pragma once
#include "core/integrate/Integrator.h"
#include "core/integrate/march/SampleRecorder.h"

namespace volref {

class LineIntegralIntegrator final : public OneLoopIntegrator<LineIntegralIntegrator> {
public:
    LineIntegralIntegrator(const IntegrationContext& ctx, bool mean) : OneLoopIntegrator(ctx), mean_(mean) {}

private:
    friend class OneLoopIntegrator<LineIntegralIntegrator>;
    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    bool mean_;
};

}  // namespace volref
