#include "core/integrate/CompositeIntegrator.h"

#include "core/integrate/FastProfile.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "core/integrate/CompensatedSum.h"
#include "core/integrate/SegmentWalk.h"
#include "transfer/OpacityCorrection.h"

namespace volref {

namespace {

using namespace segment_walk;

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

// With Rec::kOn the loops below also fill one SampleRecord per visited segment; every statement of
// the plain loop is unchanged (the records only read its state).
template <class Rec>
PixelValue CompositeIntegrator::front_to_back(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    const bool terminate = ctx_.render.early_termination.has_value();
    const double threshold = terminate ? *ctx_.render.early_termination : 0.0;
    CompensatedSum tau;
    glm::dvec3 C(0.0);
    bool opaque = false;
    ForwardSegmentWalk walk(ctx_.macrocells, ray, intervals, ctx_.step);
    Segment s;
    while (walk.next(s)) {
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        PipelineSample p;
        if constexpr (Rec::kOn) {
            rec.begin(r, s.t0, s.t1);
            p = ctx_.pipeline.sample_detailed(ray, s.midpoint(), SamplePipeline::Use::Composite, r.sample);
            r.composited = true;
        } else {
            p = ctx_.pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
        }
        const double a = p.opacity;
        if (a <= 0.0) {
            if constexpr (Rec::kOn) {  // nothing changes
                r.transmittance_before = r.transmittance_after = std::exp(-tau.value());
                r.accumulated = glm::dvec4(C, -std::expm1(-tau.value()));
                rec.recorder.record(r);
            }
            continue;
        }
        const double T = std::exp(-tau.value());
        if (a >= 1.0) {  // opaque: alpha = 1, nothing behind is visible
            C += T * p.color;
            opaque = true;
            if constexpr (Rec::kOn) {
                r.tau = std::numeric_limits<double>::infinity();
                r.alpha = 1.0;
                r.transmittance_before = T;
                r.transmittance_after = 0.0;
                r.accumulated = glm::dvec4(C, 1.0);
                rec.recorder.record(r);
            }
            break;
        }
        const double tau_k = optical_depth(a, s.length(), l);
        const double alpha = -std::expm1(-tau_k);
        C += (T * alpha) * p.color;
        tau.add(tau_k);
        if constexpr (Rec::kOn) {
            r.tau = tau_k;
            r.alpha = alpha;
            r.transmittance_before = T;
            r.transmittance_after = std::exp(-tau.value());
            r.accumulated = glm::dvec4(C, -std::expm1(-tau.value()));
            rec.recorder.record(r);
        }
        if (terminate && -std::expm1(-tau.value()) > threshold) break;
    }
    PixelValue out;
    out.rgba = glm::dvec4(C, opaque ? 1.0 : -std::expm1(-tau.value()));
    return out;
}

template <class Rec>
PixelValue CompositeIntegrator::back_to_front(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    CompensatedSum tau;
    glm::dvec3 C(0.0);
    bool opaque = false;
    // The transmittance of what is composited so far (0 once a sample was opaque); records only.
    [[maybe_unused]] auto transmittance = [&] { return opaque ? 0.0 : std::exp(-tau.value()); };
    [[maybe_unused]] auto accumulated = [&] { return glm::dvec4(C, opaque ? 1.0 : -std::expm1(-tau.value())); };
    for_each_segment_reversed_skipping(ctx_.macrocells, ray, intervals, ctx_.step, [&](const Segment& s) {
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        PipelineSample p;
        if constexpr (Rec::kOn) {
            rec.begin(r, s.t0, s.t1);
            p = ctx_.pipeline.sample_detailed(ray, s.midpoint(), SamplePipeline::Use::Composite, r.sample);
            r.composited = true;
            r.transmittance_before = transmittance();
        } else {
            p = ctx_.pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
        }
        const double a = p.opacity;
        if (a <= 0.0) {
            if constexpr (Rec::kOn) {
                r.transmittance_after = transmittance();
                r.accumulated = accumulated();
                rec.recorder.record(r);
            }
            return true;
        }
        if (a >= 1.0) {
            C = p.color;
            opaque = true;
            if constexpr (Rec::kOn) {
                r.tau = std::numeric_limits<double>::infinity();
                r.alpha = 1.0;
                r.transmittance_after = 0.0;
                r.accumulated = accumulated();
                rec.recorder.record(r);
            }
            return true;
        }
        const double tau_k = optical_depth(a, s.length(), l);
        const double alpha = -std::expm1(-tau_k);
        C = alpha * p.color + (1.0 - alpha) * C;
        tau.add(tau_k);
        if constexpr (Rec::kOn) {
            r.tau = tau_k;
            r.alpha = alpha;
            r.transmittance_after = transmittance();
            r.accumulated = accumulated();
            rec.recorder.record(r);
        }
        return true;
    });
    PixelValue out;
    out.rgba = glm::dvec4(C, opaque ? 1.0 : -std::expm1(-tau.value()));
    return out;
}

}  // namespace volref
