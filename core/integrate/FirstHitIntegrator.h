// FirstHitIntegrator: the first crossing of the isovalue (conventions section 6).
//
// On each interval [t0, t1] (front to back) the field g(t) = f(t) - iso is evaluated at the segment
// endpoints of Segments.h (t0, t0 + h, ..., t1). The first endpoint where g is 0, or where the sign
// of g differs from the previous endpoint's, brackets the crossing; bisection halves the bracket
// (keeping the sign change) until it is at most kFirstHitRelativeTolerance * (t1 - t0) wide and the
// hit is its midpoint. The pixel is the classification's colour there, shaded when the scene is,
// with alpha 1 (the surface is opaque; the opacity is not used); depth = t of the hit, the distance from
// the ray's origin (eye, or eye's plane for orthographic cameras) along the unit direction.
// Misses are (0, 0, 0, 0) with depth +inf. Two crossings inside one step are not seen (the
// adaptive integrator of a later issue isolates the roots of the cubic).
#pragma once
#include "core/integrate/Integrator.h"

namespace volref {

class FirstHitIntegrator final : public Integrator {
public:
    using Integrator::Integrator;
    PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const override;
    bool writes_depth() const override { return true; }
};

}  // namespace volref
