#include "core/integrate/CompositeIntegrator.h"

#include <cmath>

#include "core/integrate/CompensatedSum.h"
#include "core/integrate/Segments.h"
#include "transfer/OpacityCorrection.h"

namespace volref {

PixelValue CompositeIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    return ctx_.render.order == CompositeOrder::FrontToBack ? front_to_back(ray, intervals)
                                                            : back_to_front(ray, intervals);
}

PixelValue CompositeIntegrator::front_to_back(const Ray& ray, const std::vector<Interval>& intervals) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    const bool terminate = ctx_.render.early_termination.has_value();
    const double threshold = terminate ? *ctx_.render.early_termination : 0.0;
    CompensatedSum tau;
    glm::dvec3 C(0.0);
    bool opaque = false;
    for_each_segment(intervals, ctx_.step, [&](const Segment& s) {
        const PipelineSample p = ctx_.pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
        const double a = p.opacity;
        if (a <= 0.0) return true;
        const double T = std::exp(-tau.value());
        if (a >= 1.0) {  // opaque: alpha = 1, nothing behind is visible
            C += T * p.color;
            opaque = true;
            return false;
        }
        const double tau_k = optical_depth(a, s.length(), l);
        const double alpha = -std::expm1(-tau_k);
        C += (T * alpha) * p.color;
        tau.add(tau_k);
        return !(terminate && -std::expm1(-tau.value()) > threshold);
    });
    PixelValue out;
    out.rgba = glm::dvec4(C, opaque ? 1.0 : -std::expm1(-tau.value()));
    return out;
}

PixelValue CompositeIntegrator::back_to_front(const Ray& ray, const std::vector<Interval>& intervals) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    CompensatedSum tau;
    glm::dvec3 C(0.0);
    bool opaque = false;
    for_each_segment_reversed(intervals, ctx_.step, [&](const Segment& s) {
        const PipelineSample p = ctx_.pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
        const double a = p.opacity;
        if (a <= 0.0) return true;
        if (a >= 1.0) {
            C = p.color;
            opaque = true;
            return true;
        }
        const double tau_k = optical_depth(a, s.length(), l);
        const double alpha = -std::expm1(-tau_k);
        C = alpha * p.color + (1.0 - alpha) * C;
        tau.add(tau_k);
        return true;
    });
    PixelValue out;
    out.rgba = glm::dvec4(C, opaque ? 1.0 : -std::expm1(-tau.value()));
    return out;
}

}  // namespace volref
