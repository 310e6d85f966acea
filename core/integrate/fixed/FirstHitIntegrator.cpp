#include "core/integrate/fixed/FirstHitIntegrator.h"

#include "core/integrate/march/SpanStates.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/Conventions.h"
#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/integrate/adaptive/AdaptiveCellWalk.h"
#include "core/integrate/adaptive/CellCubic.h"
#include "core/integrate/march/March.h"
#include "core/sample/VolumeSampler.h"

namespace volref {

namespace {

int sign(double x) { return (x > 0.0) - (x < 0.0); }

}  // namespace

std::optional<double> first_crossing_exact(const VolumeSampler& sampler, const Ray& ray, double t0, double t1,
                                           double iso, const RaySpan& span) {
    // Non-finite values (NaN, +-Inf voxels) never cross: parts with a non-finite end are passed over.
    auto at_t0 = [&] { return sampler.trilinear(ray.at(t0)) - iso == 0.0; };
    if (span.whole() && at_t0()) return t0;
    std::vector<double> cuts;
    grid_cuts(ray, t0, t1, sampler.volume(), 0.0, cuts);
    for (std::size_t p = 0; p + 1 < cuts.size(); ++p) {
        if (!span.whole()) {  // the pieces whose midpoints the span owns; t0 is the first piece's
            if (!span.owns(0.5 * (cuts[p] + cuts[p + 1]))) continue;
            if (p == 0 && at_t0()) return t0;
        }
        if (const auto hit = first_crossing_in_cell(sampler, ray, cuts[p], cuts[p + 1], iso)) return hit;
    }
    return std::nullopt;
}

std::optional<double> first_crossing_in_cell(const VolumeSampler& sampler, const Ray& ray, double ta, double tb, double iso) {
    auto g = [&](double t) { return sampler.trilinear(ray.at(t)) - iso; };
    double ex[2];
    const int ne = cubic_extrema(cell_cubic(sampler, ray, ta, tb), tb - ta, ex);
    // The monotone parts' ends: ta, ta + extrema, tb.
    double ts[4];
    int n = 0;
    ts[n++] = ta;
    for (int k = 0; k < ne; ++k)
        if (ta + ex[k] > ts[n - 1] && ta + ex[k] < tb) ts[n++] = ta + ex[k];
    ts[n++] = tb;
    // The piece's own ends, read in its cell (piece_end, CellCubic.h).
    double ga = piece_end(g, ta, tb).second;
    for (int m = 0; m + 1 < n; ++m) {
        const double a = ts[m], b = ts[m + 1], gb = m + 2 == n ? piece_end(g, b, a).second : g(b);
        if (!std::isfinite(ga) || !std::isfinite(gb)) {
            ga = gb;
            continue;
        }
        if (ga == 0.0) return a;
        if (gb == 0.0) return b;
        if (sign(ga) != sign(gb)) return bisect_to_rounding(g, a, b, sign(ga));
        ga = gb;
    }
    return std::nullopt;
}

FirstHitIntegrator::FirstHitIntegrator(const IntegrationContext& ctx) : OneLoopIntegrator(ctx) {
    const VolumeSampler* s = ctx.pipeline.view().cartesian;
    if (s && s->interpolation() == Interpolation::Trilinear) trilinear_ = s;
    adaptive_ = ctx.render.integrator == IntegrationMethod::Adaptive;
    traits_.resumable = true;
    traits_.writes_depth = true;
    traits_.writes_error = adaptive_;
    if (adaptive_ && !trilinear_)
        throw Error("render.integrator: \"adaptive\" first-hit needs a Cartesian grid with trilinear interpolation "
                    "(the crossing is a root of the cell's cubic)");
}

// A whole ray is its one span, finished; there is no traced loop.
PixelValue FirstHitIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, NoRecording&) const {
    RayState state;
    integrate_span_impl(ray, intervals, RaySpan{}, state);
    return finish(ray, intervals, state);
}

// The one search: the brackets (segments) or cell pieces whose midpoints `span` owns, front to back;
// a hit is classified here and stops the ray (hit_state, march/SpanStates.h).
void FirstHitIntegrator::integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                             RayState& state) const {
    if (state.stopped != 0.0) return;
    const double iso = *ctx_.render.isovalue;
    auto g = [&](double t) { return ctx_.field(ray, t) - iso; };
    std::optional<double> hit;
    if (adaptive_) {
        for (const Interval& iv : intervals)
            if ((hit = first_crossing_exact(*trilinear_, ray, iv.t0, iv.t1, iso, span))) break;
    } else {
        // The sign of g at the owned segments' ends, bracketed segment by segment from each interval's
        // first owned segment's start (a crossing exactly at an interval's entry is a hit there).
        std::size_t current = intervals.size();
        double ta = 0.0, ga = 0.0;
        march(intervals, {.step = ctx_.step, .span = span}, [&](const MarchSample& m) {
            if (m.interval != current) {
                current = m.interval;
                ta = m.s.t0;
                ga = g(ta);
                if (m.k == 0 && ga == 0.0) {
                    hit = ta;
                    return false;
                }
            }
            const double tb = m.s.t1, gb = g(tb);
            hit = bracket_crossing(g, trilinear_, ray, ta, ga, tb, gb, iso, intervals[m.interval].length());
            ta = tb;
            ga = gb;
            return !hit;
        });
    }
    if (hit) hit_state::save(*hit, ctx_.pipeline.sample(ray, *hit, SamplePipeline::Use::Surface).color, state);
}

void FirstHitIntegrator::merge_spans(RayState& front, const RayState& back) const { hit_state::merge(front, back); }

PixelValue FirstHitIntegrator::finish(const Ray&, const std::vector<Interval>&, const RayState& state) const {
    PixelValue out;
    if (hit_state::hit(state)) {
        out.rgba = glm::dvec4(state.v[2], state.v[3], state.v[4], 1.0);
        out.depth = state.v[1];
    }
    out.error = conventions::kRoundingErrorRelative * (1.0 + std::max({std::fabs(out.rgba.r), std::fabs(out.rgba.g),
                                                                       std::fabs(out.rgba.b), std::fabs(out.rgba.a)}));
    return out;
}

}  // namespace volref
