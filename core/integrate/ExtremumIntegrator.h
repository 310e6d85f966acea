// ExtremumIntegrator: maximum (mip) or minimum (minip) intensity projection (conventions section 6).
// The extremum of the reconstructed value over the ray's sample points (the segment midpoints of
// Segments.h); the pixel is the classification's colour and opacity at that sample (the first of
// equal extrema), premultiplied: (a c, a), unshaded. A ray with no interval is (0, 0, 0, 0).
#pragma once
#include "core/integrate/Integrator.h"

namespace volref {

class ExtremumIntegrator final : public Integrator {
public:
    ExtremumIntegrator(const IntegrationContext& ctx, bool maximum) : Integrator(ctx), maximum_(maximum) {}
    PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const override;

private:
    bool maximum_;
};

}  // namespace volref
