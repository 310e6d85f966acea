#include "core/integrate/CompositeIntegrator.h"

#include <algorithm>
#include <cmath>

#include "core/integrate/CompensatedSum.h"
#include "core/integrate/Segments.h"
#include "core/sample/MacrocellGrid.h"
#include "transfer/OpacityCorrection.h"

namespace volref {

namespace {

// The smallest k in [0, n] whose midpoint t0 + (k + 1/2) h is >= t, estimated (rounded); the walks
// below check what they skip against macrocell_at.
std::int64_t segment_at_or_after(const Interval& iv, double step, double t, std::int64_t n) {
    const double k = std::ceil((t - iv.t0) / step - 0.5);
    if (!(k > 0.0)) return 0;  // also -inf and NaN
    if (k >= double(n)) return n;
    return std::int64_t(k);
}

// The macrocell in which the pipeline samples segment k (at ray.at(midpoint)).
MacrocellGrid::Index macrocell_of(const MacrocellGrid& grid, const Ray& ray, const Interval& iv, double step,
                                  std::int64_t k, std::int64_t n) {
    return grid.macrocell_at(ray.at(segment(iv, step, k, n).midpoint()));
}

// for_each_segment without the segments in empty macrocells (CompositeIntegrator.h).
template <typename Fn>
void for_each_segment_skipping(const MacrocellGrid* grid, const Ray& ray, const std::vector<Interval>& intervals,
                               double step, Fn&& fn) {
    if (!grid) return for_each_segment(intervals, step, fn);
    for (const Interval& iv : intervals) {
        const std::int64_t n = segment_count(iv, step);
        std::int64_t k = 0;
        while (k < n) {
            const MacrocellGrid::Index m = macrocell_of(*grid, ray, iv, step, k, n);
            std::int64_t end = std::clamp<std::int64_t>(segment_at_or_after(iv, step, grid->exit_distance(ray, m), n), k + 1, n);
            if (grid->empty(m)) {
                if (end - 1 > k && macrocell_of(*grid, ray, iv, step, end - 1, n) != m) {
                    std::int64_t in = k, out = end - 1;  // in m, not in m
                    while (out - in > 1) {
                        const std::int64_t mid = in + (out - in) / 2;
                        (macrocell_of(*grid, ray, iv, step, mid, n) == m ? in : out) = mid;
                    }
                    end = in + 1;
                }
                k = end;  // segments k .. end - 1 lie in m: opacity 0
                continue;
            }
            for (; k < end; ++k)
                if (!fn(segment(iv, step, k, n))) return;
        }
    }
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
            std::int64_t begin = std::clamp<std::int64_t>(segment_at_or_after(iv, step, grid->entry_distance(ray, m), n), 0, k);
            if (grid->empty(m)) {
                if (begin < k && macrocell_of(*grid, ray, iv, step, begin, n) != m) {
                    std::int64_t out = begin, in = k;  // not in m, in m
                    while (in - out > 1) {
                        const std::int64_t mid = out + (in - out) / 2;
                        (macrocell_of(*grid, ray, iv, step, mid, n) == m ? in : out) = mid;
                    }
                    begin = in;
                }
                k = begin - 1;  // segments begin .. k lie in m: opacity 0
                continue;
            }
            for (; k >= begin; --k)
                if (!fn(segment(iv, step, k, n))) return;
        }
    }
}

}  // namespace

PixelValue CompositeIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    return ctx_.render.order == CompositeOrder::FrontToBack ? front_to_back(ray, intervals)
                                                            : back_to_front(ray, intervals);
}

PixelValue CompositeIntegrator::front_to_back(const Ray& ray, const std::vector<Interval>& intervals) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    const bool terminate = ctx_.render.early_termination.has_value();
    const double threshold = terminate ? *ctx_.render.early_termination : 0.0;
    CompensatedSum tau;
    glm::dvec3 C(0.0);
    bool opaque = false;
    for_each_segment_skipping(ctx_.macrocells, ray, intervals, ctx_.step, [&](const Segment& s) {
        const PipelineSample p = ctx_.pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
        const double a = p.opacity;
        if (a <= 0.0) return true;
        const double T = std::exp(-tau.value());
        if (a >= 1.0) {  // opaque: alpha = 1, nothing behind is visible
            C += T * p.color;
            opaque = true;
            return false;
        }
        const double tau_k = optical_depth(a, s.length(), l);
        const double alpha = -std::expm1(-tau_k);
        C += (T * alpha) * p.color;
        tau.add(tau_k);
        return !(terminate && -std::expm1(-tau.value()) > threshold);
    });
    PixelValue out;
    out.rgba = glm::dvec4(C, opaque ? 1.0 : -std::expm1(-tau.value()));
    return out;
}

PixelValue CompositeIntegrator::back_to_front(const Ray& ray, const std::vector<Interval>& intervals) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    CompensatedSum tau;
    glm::dvec3 C(0.0);
    bool opaque = false;
    for_each_segment_reversed_skipping(ctx_.macrocells, ray, intervals, ctx_.step, [&](const Segment& s) {
        const PipelineSample p = ctx_.pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
        const double a = p.opacity;
        if (a <= 0.0) return true;
        if (a >= 1.0) {
            C = p.color;
            opaque = true;
            return true;
        }
        const double tau_k = optical_depth(a, s.length(), l);
        const double alpha = -std::expm1(-tau_k);
        C = alpha * p.color + (1.0 - alpha) * C;
        tau.add(tau_k);
        return true;
    });
    PixelValue out;
    out.rgba = glm::dvec4(C, opaque ? 1.0 : -std::expm1(-tau.value()));
    return out;
}

}  // namespace volref
