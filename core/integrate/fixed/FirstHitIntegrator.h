// FirstHitIntegrator: the first crossing of the isovalue (conventions section 6).
//
// On each interval [t0, t1] (front to back) the field g(t) = f(t) - iso is evaluated at the segment
// endpoints of SamplePlacement.h (t0, t0 + h, ..., t1). The first endpoint where g is 0, or where the sign
// of g differs from the previous endpoint's, brackets the crossing; bisection halves the bracket
// (keeping the sign change) until it is at most kFirstHitRelativeTolerance * (t1 - t0) wide and the
// hit is its midpoint. The pixel is the classification's colour there, shaded when the scene is,
// with alpha 1 (the surface is opaque; the opacity is not used); depth = t of the hit, the distance from
// the ray's origin (eye, or eye's plane for orthographic cameras) along the unit direction.
// Misses are (0, 0, 0, 0) with depth +inf. Two crossings inside one step are not seen.
//
// Cartesian grids with trilinear interpolation: the crossing inside the bracket is instead the first
// root of the cell cubics (first_crossing_exact below), exact to rounding. With render.integrator
// "adaptive" the whole interval is searched that way (no step: no crossing is missed, however close
// two are), and the "error" channel holds the rounding bound; other grids are an error there.
#pragma once
#include <cmath>
#include <optional>

#include "core/Conventions.h"
#include "core/integrate/Integrator.h"

namespace volref {

class VolumeSampler;

class FirstHitIntegrator final : public OneLoopIntegrator<FirstHitIntegrator> {
public:
    explicit FirstHitIntegrator(const IntegrationContext& ctx);
    // Whole rays and spans (RayBatch, OneLoopIntegrator): the search over a span's brackets or pieces; a
    // hit stops the ray. The depth channel always, the error channel with render.integrator "adaptive".
    void merge_spans(RayState& front, const RayState& back) const override;
    PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const override;

private:
    friend class OneLoopIntegrator<FirstHitIntegrator>;
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, NoRecording& rec) const;
    void integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, RayState& state) const;
    const VolumeSampler* trilinear_ = nullptr;  // Cartesian trilinear sampler, else null
    bool adaptive_ = false;
};

// The first t in [t0, t1] where the trilinear field f of `sampler` crosses (or touches) `iso`, exact
// to rounding (Marmitt et al. 2004): the ray is cut at cell faces (AdaptiveCellWalk.h); in each cell
// f - iso is a cubic (CellCubic.h) whose extrema cut the piece into monotone parts; the first part
// whose ends (evaluated by the sampler) have a zero or a sign change holds the first crossing, which
// bisection narrows until no double lies between the bracket's ends. None: no crossing.
std::optional<double> first_crossing_exact(const VolumeSampler& sampler, const Ray& ray, double t0, double t1,
                                           double iso, const RaySpan& span = RaySpan{});
// Its loop body: the first crossing inside one piece [ta, tb] between two grid planes (one cell), or
// none (first_crossing_exact calls it for each piece its span owns and tests g(t0) = 0 first).
std::optional<double> first_crossing_in_cell(const VolumeSampler& sampler, const Ray& ray, double ta, double tb, double iso);

// One bracket [ta, tb] of the fixed-step search, g = f - iso with ga = g(ta), gb = g(tb): the crossing
// in it, or none. A non-finite end never crosses (trilinear: the bracket's finite cells are searched
// exactly, so a NaN end does not hide a crossing beside it); gb = 0: tb; a sign change: the first root
// of the cell cubics (trilinear, `trilinear` non-null), else bisection keeping the sign change until
// the bracket is at most kFirstHitRelativeTolerance * interval_length wide, the hit its midpoint.
// ga = 0 is the caller's to test (only at an interval's first end: inside, ga is the last bracket's gb).
// FirstHitIntegrator::integrate_span searches with it (the whole ray, or volref-mpi's span of it).
template <class G>
std::optional<double> bracket_crossing(const G& g, const VolumeSampler* trilinear, const Ray& ray, double ta, double ga,
                                       double tb, double gb, double iso, double interval_length) {
    auto sign = [](double x) { return (x > 0.0) - (x < 0.0); };
    if (!std::isfinite(ga) || !std::isfinite(gb)) {
        if (trilinear) return first_crossing_exact(*trilinear, ray, ta, tb, iso);
        return std::nullopt;
    }
    if (gb == 0.0) return tb;
    if (sign(gb) == sign(ga)) return std::nullopt;
    if (trilinear)
        if (const std::optional<double> hit = first_crossing_exact(*trilinear, ray, ta, tb, iso)) return hit;
    double lo = ta, hi = tb, glo = ga;
    const double tol = conventions::kFirstHitRelativeTolerance * interval_length;
    for (int it = 0; it < 200 && hi - lo > tol; ++it) {
        const double m = 0.5 * (lo + hi), gm = g(m);
        if (gm == 0.0) {
            lo = hi = m;
            break;
        }
        if (sign(gm) == sign(glo)) {
            lo = m;
            glo = gm;
        } else {
            hi = m;
        }
    }
    return 0.5 * (lo + hi);
}

}  // namespace volref
