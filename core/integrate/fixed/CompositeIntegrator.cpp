#include "core/integrate/fixed/CompositeIntegrator.h"

#include "core/integrate/packet/FastProfile.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "core/integrate/march/March.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/SpanStates.h"

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

}  // namespace

void CompositeIntegrator::run(const RayBatch& b) const {
    const bool packets = packet_ && (b.simd || packets_only_);
    if (b.recorder) {
        if (packets_only_) fast_profile_not_traced();
        Recording rec{*b.recorder};
        b.out[0] = whole_ray(b.rays[0], b.intervals[0], rec);
        return;
    }
    if (b.resuming()) {
        if (packets) return composite_packet(ctx_.pipeline.view(), *packet_, b.rays, b.intervals, nullptr, b.count, b.spans, b.states);
        for (int i = 0; i < b.count; ++i) resume(b.rays[i], b.intervals[i], b.spans[i], b.states[i]);
        return;
    }
    if (packets) return composite_packet(ctx_.pipeline.view(), *packet_, b.rays, b.intervals, b.out, b.count);
    NoRecording rec;
    for (int i = 0; i < b.count; ++i) b.out[i] = whole_ray(b.rays[i], b.intervals[i], rec);
}

template <class Rec>
PixelValue CompositeIntegrator::whole_ray(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    PixelValue out;
    if (ctx_.render.order == CompositeOrder::FrontToBack) {
        FrontToBack<Scalar> acc;
        front_to_back(ray, intervals, RaySpan{}, acc, rec);
        out.rgba = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
    } else {
        BackToFront<Scalar> acc;
        back_to_front(ray, intervals, RaySpan{}, acc, rec);
        out.rgba = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
    }
    return out;
}

// Front to back: the state is FrontToBack's, resumed (composite_state, march/SpanStates.h). Back to
// front: the span's part from a fresh BackToFront, put behind the state.
void CompositeIntegrator::resume(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                 RayState& state) const {
    if (state.stopped != 0.0) return;
    NoRecording rec;
    if (ctx_.render.order == CompositeOrder::FrontToBack) {
        FrontToBack<Scalar> acc;
        composite_state::load(acc, state);
        const bool stopped = front_to_back(ray, intervals, span, acc, rec);
        composite_state::save(acc, state);
        state.stopped = stopped ? 1.0 : 0.0;
    } else {
        BackToFront<Scalar> acc;
        back_to_front(ray, intervals, span, acc, rec);
        RayState part;
        composite_state::save_part(glm::dvec3(acc.color(0), acc.color(1), acc.color(2)), acc.optical_depth(), acc.opaque(),
                                   part);
        composite_state::merge(state, part);
    }
}

void CompositeIntegrator::merge_spans(RayState& front, const RayState& back) const {
    if (packets_only_) product_state::merge(front, back);
    else composite_state::merge(front, back);
}

PixelValue CompositeIntegrator::finish(const Ray&, const std::vector<Interval>&, const RayState& state) const {
    PixelValue out;
    out.rgba = packets_only_ ? product_state::rgba(state) : composite_state::rgba(state);
    return out;
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
bool CompositeIntegrator::front_to_back(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                        FrontToBack<Scalar>& acc, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    const Termination& stop = termination_;
    bool stopped = false;
    march(intervals, {.step = ctx_.step, .span = span, .skip = ctx_.macrocells, .ray = &ray}, [&](const MarchSample& m) {
        const Segment& s = m.s;
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        const PipelineSample p = composite_sample(ctx_.pipeline, ray, s, rec, r, acc);
        if (!(p.opacity > 0.0)) {
            if constexpr (Rec::kOn) {  // nothing changes
                r.transmittance_after = acc.transmittance();
                r.accumulated = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.partial_alpha());
                rec.recorder.record(r);
            }
            return true;
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
        stopped = o.solid || acc.stops(o.partial, stop);  // opaque: nothing behind is visible
        return !stopped;
    });
    return stopped;
}

template <class Rec>
void CompositeIntegrator::back_to_front(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                        BackToFront<Scalar>& acc, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    [[maybe_unused]] auto accumulated = [&] { return glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha()); };
    const MarchOptions o{.step = ctx_.step, .span = span, .order = MarchOrder::BackToFront, .skip = ctx_.macrocells, .ray = &ray};
    march(intervals, o, [&](const MarchSample& m) {
        const Segment& s = m.s;
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
}

}  // namespace volref
