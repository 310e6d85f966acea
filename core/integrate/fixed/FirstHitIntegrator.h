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
#include <optional>

#include "core/integrate/Integrator.h"

namespace volref {

class VolumeSampler;

class FirstHitIntegrator final : public Integrator {
public:
    explicit FirstHitIntegrator(const IntegrationContext& ctx);
    PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const override;
    bool writes_depth() const override { return true; }
    bool writes_error() const override { return adaptive_; }

private:
    const VolumeSampler* trilinear_ = nullptr;  // Cartesian trilinear sampler, else null
    bool adaptive_ = false;
};

// The first t in [t0, t1] where the trilinear field f of `sampler` crosses (or touches) `iso`, exact
// to rounding (Marmitt et al. 2004): the ray is cut at cell faces (AdaptiveCellWalk.h); in each cell
// f - iso is a cubic (CellCubic.h) whose extrema cut the piece into monotone parts; the first part
// whose ends (evaluated by the sampler) have a zero or a sign change holds the first crossing, which
// bisection narrows until no double lies between the bracket's ends. None: no crossing.
std::optional<double> first_crossing_exact(const VolumeSampler& sampler, const Ray& ray, double t0, double t1,
                                           double iso);

}  // namespace volref
