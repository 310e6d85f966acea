#include "core/integrate/fixed/LineIntegralIntegrator.h"

#include "core/integrate/march/SpanStates.h"

#include <cmath>

#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/March.h"
#include "core/integrate/march/Accumulators.h"

namespace volref {

// With Rec::kOn each record carries the sample's value and coordinate s(v) and the projection of the
// ray so far (g of the segments up to this one); no classification is involved.
template <class Rec>
PixelValue LineIntegralIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    PixelValue out;
    if (intervals.empty()) return out;
    LineIntegral<CompensatedSum> acc;
    line(ray, intervals, RaySpan{}, acc, rec);
    const double g = result(acc);
    out.rgba = glm::dvec4(g, g, g, 1.0);
    return out;
}

double LineIntegralIntegrator::result(const LineIntegral<CompensatedSum>& acc) const {
    return mean_ ? acc.mean() : ctx_.render.gain * acc.integral();
}

// The one loop: the samples `span` owns added to `acc`.
template <class Rec>
void LineIntegralIntegrator::line(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                  LineIntegral<CompensatedSum>& acc, Rec& rec) const {
    [[maybe_unused]] auto result = [&] { return this->result(acc); };
    march(intervals, {.step = ctx_.step, .span = span}, [&](const MarchSample& m) {
        const Segment& s = m.s;
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
}

// Resumable: the sums continue (line_state, march/SpanStates.h).
void LineIntegralIntegrator::integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals,
                                                 const RaySpan& span, RayState& state) const {
    LineIntegral<CompensatedSum> acc(line_state::integral(state), line_state::length(state));
    NoRecording rec;
    line(ray, intervals, span, acc, rec);
    line_state::save(acc.integral_sum(), acc.length_sum(), 0.0, state);
}

void LineIntegralIntegrator::merge_spans(RayState& front, const RayState& back) const { line_state::merge(front, back); }

PixelValue LineIntegralIntegrator::finish(const Ray&, const std::vector<Interval>& intervals, const RayState& state) const {
    PixelValue out;
    if (intervals.empty()) return out;
    const double g = result(LineIntegral<CompensatedSum>(line_state::integral(state), line_state::length(state)));
    out.rgba = glm::dvec4(g, g, g, 1.0);
    return out;
}

// The two loops OneLoopIntegrator calls (its virtual functions are instantiated where the class is
// constructed, which does not see this definition).
template PixelValue LineIntegralIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, NoRecording&) const;
template PixelValue LineIntegralIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, Recording&) const;

}  // namespace volref
