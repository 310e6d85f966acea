#include "core/integrate/ExtremumIntegrator.h"

#include "core/integrate/Segments.h"

namespace volref {

PixelValue ExtremumIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    bool any = false;
    double best = 0.0;
    for_each_segment(intervals, ctx_.step, [&](const Segment& s) {
        const double v = ctx_.field(ray, s.midpoint());
        if (!any || (maximum_ ? v > best : v < best)) best = v;
        any = true;
        return true;
    });
    PixelValue out;
    if (any) {
        const double a = ctx_.transfer.opacity(best);
        out.rgba = glm::dvec4(a * ctx_.transfer.color(best), a);
    }
    return out;
}

}  // namespace volref
