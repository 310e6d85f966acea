#include "core/integrate/fixed/ExtremumIntegrator.h"

#include "core/integrate/packet/FastProfile.h"
#include "core/integrate/march/March.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/SpanStates.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace volref {

ExtremumIntegrator::ExtremumIntegrator(const IntegrationContext& ctx, bool maximum) : OneLoopIntegrator(ctx), maximum_(maximum) {
    const bool fast = ctx.lanes == IntegrationContext::Lanes::Float;
    packets_only_ = fast;
    traits_.resumable = true;
    if (const char* reason = ctx.pipeline.view().packet_unavailable(false, ctx.render.order)) {
        if (fast) fast_profile_unavailable(reason);
        return;
    }
    // Skipping: PreparedVolume builds the grid for mip / minip.
    packet_ = PacketRun{.step = ctx.step, .macrocells = ctx.macrocells, .fast = fast};
}

ExtremumIntegrator::~ExtremumIntegrator() = default;

// The packets' extrema (bitwise the scalar loop's), classified here: the pixels, or each span's
// extremum behind its state (extremum_state, march/SpanStates.h).
void ExtremumIntegrator::integrate_packets(const RayBatch& b) const {
    RayExtremum e[kMaxPacketRays];
    extremum_packet(ctx_.pipeline.view(), *packet_, maximum_, b.rays, b.intervals, e, b.count, b.spans);
    for (int i = 0; i < b.count; ++i) {
        if (!b.resuming()) b.out[i] = pixel(b.rays[i], e[i].any, e[i].t);
        else if (e[i].any) merge_extremum(b.rays[i], e[i].value, e[i].t, b.states[i]);
    }
}

void ExtremumIntegrator::integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                             RayState& state) const {
    NoRecording rec;
    const Extremum<Scalar> acc = extremum(ray, intervals, span, rec);
    if (acc.any()) merge_extremum(ray, acc.value(), acc.where(), state);
}

// A span's extremum `value` at t, classified by the span that took it, behind `state`.
void ExtremumIntegrator::merge_extremum(const Ray& ray, double value, double t, RayState& state) const {
    RayState part;
    extremum_state::save(value, t, pixel(ray, true, t).rgba, part);
    extremum_state::merge(state, part, maximum_);
}

// With Rec::kOn each sample is also classified (unshaded, for the record) and the record carries the
// extremum so far and the pixel it gives; the value is the one the plain loop reads (the same sampler
// call at the same point).
template <class Rec>
PixelValue ExtremumIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    const Extremum<Scalar> acc = extremum(ray, intervals, RaySpan{}, rec);
    return pixel(ray, acc.any(), acc.where());
}

// The one loop: the extremum over the samples `span` owns.
template <class Rec>
Extremum<Scalar> ExtremumIntegrator::extremum(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                              Rec& rec) const {
    Extremum<Scalar> acc(maximum_);
    [[maybe_unused]] glm::dvec4 so_far(0.0);
    march(intervals, {.step = ctx_.step, .span = span}, [&](const MarchSample& m) {
        const Segment& s = m.s;
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        double v;
        if constexpr (Rec::kOn) {
            rec.begin(r, s.t0, s.t1);
            v = ctx_.pipeline.sample_detailed(ray, s.midpoint(), SamplePipeline::Use::Unshaded, r.sample).value;
        } else {
            v = ctx_.field(ray, s.midpoint());
        }
        [[maybe_unused]] const bool taken = acc.add(true, v, s.midpoint());
        if constexpr (Rec::kOn) {
            if (taken) so_far = pixel(ray, true, acc.where()).rgba;
            r.running = acc.value();
            r.accumulated = so_far;
            rec.recorder.record(r);
        }
        return true;
    });
    return acc;
}

void ExtremumIntegrator::merge_spans(RayState& front, const RayState& back) const {
    extremum_state::merge(front, back, maximum_);
}

PixelValue ExtremumIntegrator::finish(const Ray&, const std::vector<Interval>&, const RayState& state) const {
    PixelValue out;
    if (extremum_state::seen(state)) out.rgba = extremum_state::rgba(state);
    return out;
}

PixelValue ExtremumIntegrator::pixel(const Ray& ray, bool any, double t_best) const {
    PixelValue out;
    if (any) {
        const PipelineSample p = ctx_.pipeline.sample(ray, t_best, SamplePipeline::Use::Unshaded);
        out.rgba = glm::dvec4(p.opacity * p.color, p.opacity);
    }
    return out;
}

// The two loops OneLoopIntegrator calls (its run() is instantiated where the class is constructed).
template PixelValue ExtremumIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, NoRecording&) const;
template PixelValue ExtremumIntegrator::integrate_impl(const Ray&, const std::vector<Interval>&, Recording&) const;

}  // namespace volref
