#include "core/integrate/fixed/CompositeIntegrator.h"

#include "core/integrate/packet/FastProfile.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "core/integrate/march/SegmentWalk.h"
#include "core/integrate/march/Accumulators.h"

namespace volref {

namespace {

using namespace segment_walk;

// The composite sample at segment s's midpoint. With Rec::kOn the same computation also fills the
// stages of record r and starts it (the transmittance in front of the sample: the accumulator's).
template <class Rec, class Record, class Acc>
PipelineSample composite_sample(const SamplePipeline& pipeline, const Ray& ray, const Segment& s, Rec& rec, Record& r,
                                const Acc& acc) {
    if constexpr (Rec::kOn) {
        rec.begin(r, s.t0, s.t1);
        r.composited = true;
        r.transmittance_before = acc.transmittance();
        return pipeline.sample_detailed(ray, s.midpoint(), SamplePipeline::Use::Composite, r.sample);
    } else {
        return pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
    }
}

// A composited sample's optical depth (infinite when opaque) and alpha, for its record.
void record_opacity(SampleRecord& r, const SampleOpacity<Scalar>& o) {
    r.tau = o.solid ? std::numeric_limits<double>::infinity() : o.tau;
    r.alpha = o.alpha;
}

// for_each_segment_reversed without the segments in empty macrocells.
template <typename Fn>
void for_each_segment_reversed_skipping(const MacrocellGrid* grid, const Ray& ray,
                                        const std::vector<Interval>& intervals, double step, Fn&& fn) {
    if (!grid) return for_each_segment_reversed(intervals, step, fn);
    for (auto it = intervals.rbegin(); it != intervals.rend(); ++it) {
        const Interval& iv = *it;
        const std::int64_t n = segment_count(iv, step);
        std::int64_t k = n - 1;
        while (k >= 0) {
            const MacrocellGrid::Index m = macrocell_of(*grid, ray, iv, step, k, n);
            // The estimate: segments begin .. k have their midpoints after the ray enters m.
            const std::int64_t begin =
                std::clamp<std::int64_t>(segment_at_or_after(iv, step, grid->entry_distance(ray, m), n), 0, k);
            if (grid->empty(m)) {
                // Indices mirrored (j -> k - j) so that the run again starts at 0 and grows.
                auto in_m = [&](std::int64_t j) { return macrocell_of(*grid, ray, iv, step, k - j, n) == m; };
                std::int64_t in = k - begin, out = k + 1;
                if (in > 0 && !in_m(in)) {
                    out = in;  // the estimate is too long
                    in = 0;
                } else {  // too short? gallop backward
                    for (std::int64_t d = 1; in + d <= k; d *= 2) {
                        if (!in_m(in + d)) {
                            out = in + d;
                            break;
                        }
                        in += d;
                    }
                }
                k -= last_in_run(in, out, in_m) + 1;  // every segment down to there lies in m: opacity 0
                continue;
            }
            for (; k >= begin; --k)
                if (!fn(segment(iv, step, k, n))) return;
        }
    }
}

}  // namespace

PixelValue CompositeIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    if (packet_ && packet_->fast) {  // the fast profile has only its packet path
        PixelValue out;
        composite_packet(*packet_, &ray, &intervals, &out, 1);
        return out;
    }
    NoRecording rec;
    return ctx_.render.order == CompositeOrder::FrontToBack ? front_to_back(ray, intervals, rec)
                                                            : back_to_front(ray, intervals, rec);
}

PixelValue CompositeIntegrator::integrate_traced(const Ray& ray, const std::vector<Interval>& intervals,
                                                 SampleRecorder& recorder) const {
    if (packet_ && packet_->fast) fast_profile_not_traced();
    Recording rec{recorder};
    return ctx_.render.order == CompositeOrder::FrontToBack ? front_to_back(ray, intervals, rec)
                                                            : back_to_front(ray, intervals, rec);
}

Termination early_termination(const RenderSpec& render) {
    Termination t;
    t.test_alpha_above = render.early_termination.has_value();
    t.alpha_above = render.early_termination.value_or(1.0);
    return t;
}

// With Rec::kOn the loops below also fill one SampleRecord per visited segment; every statement of
// the plain loop is unchanged (the records only read its state). The compositing is the
// accumulators' (march/Accumulators.h).
template <class Rec>
PixelValue CompositeIntegrator::front_to_back(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    const Termination stop = early_termination(ctx_.render);
    FrontToBack<Scalar> acc;
    ForwardSegmentWalk walk(ctx_.macrocells, ray, intervals, ctx_.step);
    Segment s;
    while (walk.next(s)) {
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        const PipelineSample p = composite_sample(ctx_.pipeline, ray, s, rec, r, acc);
        if (!(p.opacity > 0.0)) {
            if constexpr (Rec::kOn) {  // nothing changes
                r.transmittance_after = acc.transmittance();
                r.accumulated = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.partial_alpha());
                rec.recorder.record(r);
            }
            continue;
        }
        const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, p.opacity, s.length(), l);
        const double c[3] = {p.color.r, p.color.g, p.color.b};
        acc.add(true, o.solid, o.tau, o.alpha, c);
        if constexpr (Rec::kOn) {
            record_opacity(r, o);
            r.transmittance_after = o.solid ? 0.0 : acc.transmittance();
            r.accumulated = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
            rec.recorder.record(r);
        }
        if (o.solid || acc.stops(o.partial, stop)) break;  // opaque: nothing behind is visible
    }
    PixelValue out;
    out.rgba = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
    return out;
}

template <class Rec>
PixelValue CompositeIntegrator::back_to_front(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    BackToFront<Scalar> acc;
    [[maybe_unused]] auto accumulated = [&] { return glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha()); };
    for_each_segment_reversed_skipping(ctx_.macrocells, ray, intervals, ctx_.step, [&](const Segment& s) {
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        const PipelineSample p = composite_sample(ctx_.pipeline, ray, s, rec, r, acc);
        if (p.opacity > 0.0) {
            const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, p.opacity, s.length(), l);
            const double c[3] = {p.color.r, p.color.g, p.color.b};
            acc.add(true, o.solid, o.tau, o.alpha, c);
            if constexpr (Rec::kOn) record_opacity(r, o);
        }
        if constexpr (Rec::kOn) {
            r.transmittance_after = acc.transmittance();
            r.accumulated = accumulated();
            rec.recorder.record(r);
        }
        return true;
    });
    PixelValue out;
    out.rgba = accumulated();
    return out;
}

}  // namespace volref
