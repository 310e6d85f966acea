#include "core/integrate/fixed/LineIntegralIntegrator.h"

#include <cmath>

#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/integrate/march/Accumulators.h"

namespace volref {

// With Rec::kOn each record carries the sample's value and coordinate s(v) and the projection of the
// ray so far (g of the segments up to this one); no classification is involved.
template <class Rec>
PixelValue LineIntegralIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    PixelValue out;
    if (intervals.empty()) return out;
    LineIntegral<CompensatedSum> acc;
    auto result = [&] { return mean_ ? acc.mean() : ctx_.render.gain * acc.integral(); };
    for_each_segment(intervals, ctx_.step, [&](const Segment& s) {
        const double v = ctx_.field(ray, s.midpoint());
        const double coordinate = ctx_.pipeline.classifier().coordinate(v);
        acc.add(std::isfinite(coordinate) ? coordinate * s.length() : 0.0, s.length());  // non-finite: 0 (docs/accuracy.md)
        if constexpr (Rec::kOn) {
            SampleRecord r;
            rec.begin(r, s.t0, s.t1);
            r.sample.position = ray.at(s.midpoint());
            r.sample.value = v;
            r.coordinate = coordinate;
            r.running = result();
            r.accumulated = glm::dvec4(r.running, r.running, r.running, 1.0);
            rec.recorder.record(r);
        }
        return true;
    });
    const double g = result();
    out.rgba = glm::dvec4(g, g, g, 1.0);
    return out;
}

// The two loops OneLoopIntegrator calls (its virtual functions are instantiated where the class is
// constructed, which does not see this definition).
template PixelValue LineIntegralIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, NoRecording&) const;
template PixelValue LineIntegralIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, Recording&) const;

}  // namespace volref
