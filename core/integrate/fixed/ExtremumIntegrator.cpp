#include "core/integrate/fixed/ExtremumIntegrator.h"

#include "core/integrate/packet/FastProfile.h"
#include "core/integrate/packet/PacketGrid.h"
#include "core/integrate/march/March.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/SpanStates.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace volref {

ExtremumIntegrator::ExtremumIntegrator(const IntegrationContext& ctx, bool maximum) : Integrator(ctx), maximum_(maximum) {
    const bool fast = ctx.lanes == IntegrationContext::Lanes::Float;
    auto unavailable = [&](const char* reason) {
        if (fast) fast_profile_unavailable(reason);
    };
    if (const char* reason = packet_path_unavailable(ctx.pipeline, false, ctx.render.order)) {
        unavailable(reason);
        return;
    }
    const Volume& v = ctx.pipeline.cartesian_sampler()->volume();
    PacketExtremumInputs in;
    in.grid = PacketGrid::of(v);
    in.step = ctx.step;
    in.maximum = maximum;
    in.macrocells = ctx.macrocells;  // skipping (PreparedVolume builds the grid for mip / minip)
    if (fast) {
        fast_copies_ = std::make_unique<FloatCopies>();
        fast_voxels(v, *fast_copies_, &in.grid.voxels, &in.grid.voxel_type);
        in.fast = true;
    }
    packet_ = in;
}

ExtremumIntegrator::~ExtremumIntegrator() = default;

void ExtremumIntegrator::integrate_packet(const Ray* rays, const std::vector<Interval>* intervals, PixelValue* out,
                                          int count) const {
    if (!packet_) return Integrator::integrate_packet(rays, intervals, out, count);
    RayExtremum e[kMaxPacketRays];
    extremum_packet(*packet_, rays, intervals, e, count);
    for (int i = 0; i < count; ++i) out[i] = pixel(rays[i], e[i].any, e[i].t);
}

PixelValue ExtremumIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    if (packet_ && packet_->fast) {  // the fast profile has only its packet path
        PixelValue out;
        integrate_packet(&ray, &intervals, &out, 1);
        return out;
    }
    NoRecording rec;
    return integrate_impl(ray, intervals, rec);
}

PixelValue ExtremumIntegrator::integrate_traced(const Ray& ray, const std::vector<Interval>& intervals,
                                                SampleRecorder& recorder) const {
    if (packet_ && packet_->fast) fast_profile_not_traced();
    Recording rec{recorder};
    return integrate_impl(ray, intervals, rec);
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

// A span's extremum (the packet path where it applies: bitwise the scalar one), classified here,
// behind the state (extremum_state, march/SpanStates.h).
void ExtremumIntegrator::integrate_span_packet(const Ray* rays, const std::vector<Interval>* intervals, const RaySpan* spans,
                                               RayState* states, int count) const {
    RayExtremum e[kMaxPacketRays];
    if (packet_) {
        extremum_packet(*packet_, rays, intervals, e, count, spans);
    } else {
        NoRecording rec;
        for (int i = 0; i < count; ++i) {
            const Extremum<Scalar> acc = extremum(rays[i], intervals[i], spans[i], rec);
            e[i] = RayExtremum{acc.any(), acc.value(), acc.where()};
        }
    }
    for (int i = 0; i < count; ++i) {
        if (!e[i].any) continue;
        RayState part;
        extremum_state::save(e[i].value, e[i].t, pixel(rays[i], true, e[i].t).rgba, part);
        extremum_state::merge(states[i], part, maximum_);
    }
}

void ExtremumIntegrator::integrate_span(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                        RayState& state) const {
    integrate_span_packet(&ray, &intervals, &span, &state, 1);
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

}  // namespace volref
