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

// The scalar stages' composite sample at segment s's midpoint, as composite_step (Accumulators-inl.h)
// reads it: opacity() is the whole pipeline sample (value, classification, shading where the opacity is
// positive, the non-finite rule: SamplePipeline.h), colour() its colour. With Rec::kOn the same
// computation also fills the stages of record r and starts it (the transmittance in front of the
// sample: the accumulator's).
template <class Rec, class Acc>
struct PipelineCompositeSample {
    const SamplePipeline& pipeline;
    const Ray& ray;
    const Segment& s;
    Rec& rec;
    std::conditional_t<Rec::kOn, SampleRecord, char>& r;
    const Acc& acc;
    PipelineSample p;
    double opacity() {
        if constexpr (Rec::kOn) {
            rec.begin(r, s.t0, s.t1);
            r.composited = true;
            r.transmittance_before = acc.transmittance();
            p = pipeline.sample_detailed(ray, s.midpoint(), SamplePipeline::Use::Composite, r.sample);
        } else {
            p = pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
        }
        return p.opacity;
    }
    void colour(double c[3]) const {
        c[0] = p.color.r;
        c[1] = p.color.g;
        c[2] = p.color.b;
    }
};

// A trace's records of one composite step (composite_step's hooks): what the sample did to the
// accumulator. Front to back, a transparent sample reports the partial alpha and an opaque one
// transmittance 0; back to front, every sample reports the accumulator as it stands.
template <class Rec, bool kFrontToBack>
struct CompositeRecords {
    Rec& rec;
    std::conditional_t<Rec::kOn, SampleRecord, char>& r;
    template <class Acc>
    void transparent(const Acc& acc) {
        if constexpr (Rec::kOn) {  // nothing changes
            r.transmittance_after = acc.transmittance();
            double a;
            if constexpr (kFrontToBack) a = acc.partial_alpha();
            else a = acc.alpha();
            r.accumulated = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), a);
            rec.recorder.record(r);
        }
    }
    template <class Acc>
    void composited(const SampleOpacity<Scalar>& o, const Acc& acc) {
        if constexpr (Rec::kOn) {
            r.tau = o.solid ? std::numeric_limits<double>::infinity() : o.tau;
            r.alpha = o.alpha;
            r.transmittance_after = kFrontToBack && o.solid ? 0.0 : acc.transmittance();
            r.accumulated = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
            rec.recorder.record(r);
        }
    }
};

}  // namespace

void CompositeIntegrator::integrate_packets(const RayBatch& b) const {
    composite_packet(ctx_.pipeline.view(), *packet_, b.rays, b.intervals, b.resuming() ? nullptr : b.out, b.count, b.spans, b.states);
}

template <class Rec>
PixelValue CompositeIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
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
void CompositeIntegrator::integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
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

// The one step of both orders is composite_step's (march/Accumulators-inl.h); with Rec::kOn it also
// fills one SampleRecord per visited segment (the records only read its state).
template <class Rec>
bool CompositeIntegrator::front_to_back(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                        FrontToBack<Scalar>& acc, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    bool stopped = false;
    march(intervals, {.step = ctx_.step, .span = span, .skip = ctx_.macrocells, .ray = &ray}, [&](const MarchSample& m) {
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        PipelineCompositeSample<Rec, FrontToBack<Scalar>> sample{ctx_.pipeline, ray, m.s, rec, r, acc, {}};
        CompositeRecords<Rec, true> records{rec, r};
        stopped = composite_step<Scalar>(acc, sample, true, m.s.length(), l, &termination_, records);
        return !stopped;  // opaque or terminated: nothing behind is visible
    });
    return stopped;
}

template <class Rec>
void CompositeIntegrator::back_to_front(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                        BackToFront<Scalar>& acc, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    const MarchOptions o{.step = ctx_.step, .span = span, .order = MarchOrder::BackToFront, .skip = ctx_.macrocells, .ray = &ray};
    march(intervals, o, [&](const MarchSample& m) {
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        PipelineCompositeSample<Rec, BackToFront<Scalar>> sample{ctx_.pipeline, ray, m.s, rec, r, acc, {}};
        CompositeRecords<Rec, false> records{rec, r};
        composite_step<Scalar>(acc, sample, true, m.s.length(), l, nullptr, records);
        return true;
    });
}

// The two loops OneLoopIntegrator calls (its run() is instantiated where the class is constructed,
// which does not see this definition).
template PixelValue CompositeIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, NoRecording&) const;
template PixelValue CompositeIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, Recording&) const;

}  // namespace volref
