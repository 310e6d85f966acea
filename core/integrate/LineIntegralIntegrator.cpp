#include "core/integrate/LineIntegralIntegrator.h"

#include "core/integrate/CompensatedSum.h"
#include "core/integrate/Segments.h"

namespace volref {

PixelValue LineIntegralIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    PixelValue out;
    if (intervals.empty()) return out;
    CompensatedSum integral, length;
    for_each_segment(intervals, ctx_.step, [&](const Segment& s) {
        integral.add(ctx_.pipeline.classifier().coordinate(ctx_.field(ray, s.midpoint())) * s.length());
        length.add(s.length());
        return true;
    });
    const double g = mean_ ? integral.value() / length.value() : ctx_.render.gain * integral.value();
    out.rgba = glm::dvec4(g, g, g, 1.0);
    return out;
}

}  // namespace volref
