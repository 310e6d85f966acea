#include "core/integrate/ExtremumIntegrator.h"

#include "core/integrate/Segments.h"

namespace volref {

PixelValue ExtremumIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    bool any = false;
    double best = 0.0, t_best = 0.0;
    for_each_segment(intervals, ctx_.step, [&](const Segment& s) {
        const double v = ctx_.field(ray, s.midpoint());
        if (!any || (maximum_ ? v > best : v < best)) {
            best = v;
            t_best = s.midpoint();
        }
        any = true;
        return true;
    });
    PixelValue out;
    if (any) {
        const PipelineSample p = ctx_.pipeline.sample(ray, t_best, SamplePipeline::Use::Unshaded);
        out.rgba = glm::dvec4(p.opacity * p.color, p.opacity);
    }
    return out;
}

}  // namespace volref
