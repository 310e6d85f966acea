// LineIntegralIntegrator: the average and x-ray projections (conventions section 6).
// With the midpoint samples of SamplePlacement.h, I = sum_k s(v_k) d_k (a compensated sum) and L = sum_k d_k,
// where s is the transfer function's coordinate (the data value, or the normalised value for the
// normalised domain):
//   average: g = I / L,          pixel (g, g, g, 1);
//   xray:    g = gain * I,       pixel (g, g, g, 1).
// A ray with no interval is (0, 0, 0, 0).
#pragma once
#include "core/integrate/Integrator.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/SampleRecorder.h"

namespace volref {

class LineIntegralIntegrator final : public OneLoopIntegrator<LineIntegralIntegrator> {
public:
    // Resumable (march/RaySpan.h): the two sums continue span after span.
    LineIntegralIntegrator(const IntegrationContext& ctx, bool mean) : OneLoopIntegrator(ctx), mean_(mean) {
        traits_.resumable = true;
    }
    void merge_spans(RayState& front, const RayState& back) const override;
    PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const override;

private:
    friend class OneLoopIntegrator<LineIntegralIntegrator>;
    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    void integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, RayState& state) const;
    template <class Rec>
    void line(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, LineIntegral<CompensatedSum>& acc,
              Rec& rec) const;
    double result(const LineIntegral<CompensatedSum>& acc) const;
    bool mean_;
};

}  // namespace volref
